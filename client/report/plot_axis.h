// Value ranges and ticks of one plot axis, linear or logarithmic. Maps a
// data value to a fraction of the axis length; knows nothing about SVG.
#pragma once

#include <string>
#include <vector>

namespace mbopt::report {

enum class AxisKind { kLinear, kLog };

struct AxisTick {
  double value = 0.0;
  std::string label;
};

struct PlotAxis {
  AxisKind kind = AxisKind::kLinear;
  double lo = 0.0;  // for kLog: > 0
  double hi = 1.0;  // > lo
  std::vector<AxisTick> ticks;

  // Position of `value` along the axis, 0 at lo and 1 at hi; NaN when the
  // value cannot be placed (NaN, infinite, or <= 0 on a log axis). Values
  // outside [lo, hi] give fractions outside [0, 1].
  double Fraction(double value) const;
};

// A linear axis covering [data_min, data_max] (finite, either order) with
// about `target_ticks` ticks at 1, 2, 2.5 or 5 x 10^k, the range widened to
// whole ticks. `min_step` bounds the tick step from below (1 for cycle
// numbers). A degenerate range is widened around its value.
PlotAxis MakeLinearAxis(double data_min, double data_max, int target_ticks = 6,
                        double min_step = 0.0);

// A logarithmic axis covering [positive_min, positive_max] (both > 0),
// widened to whole decades; ticks at decades (every k-th when there are many)
// and at 2x and 5x when it spans at most two decades.
PlotAxis MakeLogAxis(double positive_min, double positive_max);

// True when the positive finite values among `values` span `decades` or more
// (max / min >= 10^decades): the case for a logarithmic axis.
bool SpansDecades(const std::vector<double>& values, double decades = 2.0);

}  // namespace mbopt::report
