// A small SVG line-plot writer for the report page: axes with readable
// ticks, linear or logarithmic y, series as polylines and markers, dashed
// reference lines, a legend. Output is a self-contained <svg> element
// (inline in HTML, no scripts, no external resources); all text escaped.
//
// Gaps: a point whose x or y is NaN or infinite breaks its series' line and
// is not drawn. On a logarithmic y axis a value <= 0 breaks the line too and
// is drawn as a downward triangle on the bottom edge (explained in the plot).
#pragma once

#include <limits>
#include <string>
#include <vector>

namespace mbopt::report {

enum class MarkerShape { kNone, kCircle, kHollowCircle };

struct PlotSeries {
  std::string name;
  std::string color = "#1f77b4";  // CSS colour
  std::vector<double> x;
  std::vector<double> y;          // same length as x
  bool draw_line = true;
  MarkerShape marker = MarkerShape::kCircle;
  double marker_radius_px = 3.0;
  std::string dash;               // stroke-dasharray, empty: solid
  bool in_legend = true;         // series without points are left out anyway
  // Optional, one per point: a short text drawn above and right of its
  // marker (a Pareto front's point numbers). Empty: no labels.
  std::vector<std::string> point_labels;
};

// A horizontal line at a fixed y (a threshold), dashed, labelled at its
// right end. It spans x_from <= x <= x_to (the whole axis by default); when
// x_from == x_to it marks that one x with a short bar and a diamond.
struct ReferenceLine {
  double y = 0.0;
  std::string label;
  std::string color = "#888888";
  bool extend_range = true;  // widen the y range to show it
  // Label placement, for lines that lie close together: at the left end
  // instead of the right, below the line instead of above.
  bool label_left = false;
  bool label_below = false;
  double x_from = -std::numeric_limits<double>::infinity();
  double x_to = std::numeric_limits<double>::infinity();
};

struct PlotSpec {
  std::string title;
  std::string x_label;
  std::string y_label;
  bool log_y = false;       // falls back to linear when no value is > 0
  double x_min_step = 0.0;  // 1 for integer x such as cycle numbers
  std::vector<PlotSeries> series;
  std::vector<ReferenceLine> reference_lines;
  double width_px = 1000.0;
  double height_px = 300.0;  // grown when the legend needs more
};

std::string RenderLinePlotSvg(const PlotSpec& spec);

}  // namespace mbopt::report
