#include "client/report/plot_axis.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "client/report/number_format.h"
#include "common/check.h"

namespace mbopt::report {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Smallest of 1, 2, 2.5, 5, 10 x 10^k that is >= raw.
double NiceStep(double raw) {
  const double exponent = std::floor(std::log10(raw));
  const double base = std::pow(10.0, exponent);
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    if (m * base >= raw * (1 - 1e-12)) return m * base;
  }
  return 10.0 * base;
}

}  // namespace

double PlotAxis::Fraction(double value) const {
  if (!std::isfinite(value)) return kNaN;
  if (kind == AxisKind::kLog) {
    if (value <= 0) return kNaN;
    return (std::log10(value) - std::log10(lo)) / (std::log10(hi) - std::log10(lo));
  }
  return (value - lo) / (hi - lo);
}

PlotAxis MakeLinearAxis(double data_min, double data_max, int target_ticks, double min_step) {
  MBOPT_CHECK(std::isfinite(data_min) && std::isfinite(data_max), "axis range must be finite");
  if (data_min > data_max) std::swap(data_min, data_max);
  if (target_ticks < 2) target_ticks = 2;
  double span = data_max - data_min;
  if (!(span > std::max(std::abs(data_min), std::abs(data_max)) * 1e-12)) {
    // One value (or values equal to rounding): show it in the middle.
    const double pad = data_max != 0.0 ? std::abs(data_max) * 0.1 : 1.0;
    data_min -= std::max(pad, min_step);
    data_max += std::max(pad, min_step);
  }
  // Halved before the subtraction so that data near +-DBL_MAX cannot
  // overflow the span.
  double step = NiceStep((data_max / 2 - data_min / 2) / (target_ticks - 1) * 2);
  if (min_step > 0 && step < min_step) step = NiceStep(min_step);
  PlotAxis axis;
  axis.kind = AxisKind::kLinear;
  const double first = std::floor(data_min / step + 1e-9);
  const double last = std::ceil(data_max / step - 1e-9);
  axis.lo = first * step;
  axis.hi = last * step;
  if (!(axis.hi > axis.lo)) axis.hi = axis.lo + step;
  const int count = static_cast<int>(std::llround(last - first));
  for (int k = 0; k <= count && k <= 1000; ++k) {
    const double v = (first + k) * step;
    axis.ticks.push_back({v, FormatTick(v, step)});
  }
  return axis;
}

PlotAxis MakeLogAxis(double positive_min, double positive_max) {
  MBOPT_CHECK(positive_min > 0 && positive_max > 0 && std::isfinite(positive_min) &&
                  std::isfinite(positive_max),
              "log axis range must be positive and finite");
  if (positive_min > positive_max) std::swap(positive_min, positive_max);
  int low = static_cast<int>(std::floor(std::log10(positive_min) + 1e-9));
  int high = static_cast<int>(std::ceil(std::log10(positive_max) - 1e-9));
  if (high <= low) high = low + 1;
  PlotAxis axis;
  axis.kind = AxisKind::kLog;
  axis.lo = std::pow(10.0, low);
  axis.hi = std::pow(10.0, high);
  const int decades = high - low;
  const int every = std::max(1, (decades + 7) / 8);
  for (int e = low; e <= high; ++e) {
    const double decade = std::pow(10.0, e);
    if ((e - low) % every == 0) axis.ticks.push_back({decade, FormatLogTick(decade)});
    if (decades <= 2 && e < high) {
      axis.ticks.push_back({2 * decade, FormatLogTick(2 * decade)});
      axis.ticks.push_back({5 * decade, FormatLogTick(5 * decade)});
    }
  }
  std::sort(axis.ticks.begin(), axis.ticks.end(),
            [](const AxisTick& a, const AxisTick& b) { return a.value < b.value; });
  return axis;
}

bool SpansDecades(const std::vector<double>& values, double decades) {
  double lo = std::numeric_limits<double>::infinity();
  double hi = 0.0;
  for (double v : values) {
    if (std::isfinite(v) && v > 0) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  return hi > 0 && hi / lo >= std::pow(10.0, decades);
}

}  // namespace mbopt::report
