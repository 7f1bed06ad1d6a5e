#include "client/report/response_plots.h"

namespace mbopt::report {
namespace {

constexpr const char* kInitialColor = "#7f7f7f";
constexpr const char* kInitialDash = "6 3";
constexpr const char* kFinalColor = "#1f77b4";
constexpr const char* kLimitColor = "#d62728";

PlotSeries Curve(const char* name, const char* color, const char* dash, std::vector<double> x,
                 std::vector<double> y) {
  PlotSeries s;
  s.name = name;
  s.color = color;
  s.dash = dash;
  s.marker = MarkerShape::kNone;
  s.x = std::move(x);
  s.y = std::move(y);
  return s;
}

// A curve's first point, hollow: where it starts, since an x-y curve has
// no time axis to tell its direction.
PlotSeries StartMarker(const char* color, const std::vector<double>& x, const std::vector<double>& y) {
  PlotSeries s;
  s.name = "start (t = 0)";
  s.color = color;
  s.draw_line = false;
  s.marker = MarkerShape::kHollowCircle;
  s.marker_radius_px = 4.0;
  s.in_legend = false;
  if (!x.empty() && !y.empty()) {
    s.x = {x.front()};
    s.y = {y.front()};
  }
  return s;
}

}  // namespace

PlotSpec ResponsePlotSpec(const ResponsePlot& plot) {
  PlotSpec spec;
  spec.title = plot.title;
  spec.x_label = "time [s]";
  spec.y_label = plot.unit.empty() ? "value (SI)" : "value [" + plot.unit + "]";
  spec.series = {Curve("initial design", kInitialColor, kInitialDash, plot.times_s, plot.initial),
                 Curve(plot.final_label.c_str(), kFinalColor, "", plot.times_s, plot.final)};
  for (const ResponsePlot::Limit& limit : plot.limits) {
    ReferenceLine line;
    line.y = limit.value;
    line.label = limit.label;
    line.color = kLimitColor;
    line.x_from = limit.from_s;
    line.x_to = limit.to_s;
    spec.reference_lines.push_back(line);
  }
  spec.height_px = 260.0;
  return spec;
}

PlotSpec XyPlotSpec(const XyPlot& plot) {
  PlotSpec spec;
  spec.title = plot.title;
  spec.x_label = plot.x_label;
  spec.y_label = plot.y_label;
  spec.series = {Curve("initial design", kInitialColor, kInitialDash, plot.initial_x, plot.initial_y),
                 Curve("final design", kFinalColor, "", plot.final_x, plot.final_y),
                 StartMarker(kInitialColor, plot.initial_x, plot.initial_y),
                 StartMarker(kFinalColor, plot.final_x, plot.final_y)};
  spec.height_px = 320.0;
  return spec;
}

}  // namespace mbopt::report
