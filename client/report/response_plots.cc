#include "client/report/response_plots.h"

namespace mbopt::report {

PlotSpec ResponsePlotSpec(const ResponsePlot& plot) {
  PlotSpec spec;
  spec.title = plot.title;
  spec.x_label = "time [s]";
  spec.y_label = plot.unit.empty() ? "value (SI)" : "value [" + plot.unit + "]";
  // A scalar (mass, a response of parameters) is one point per design.
  const bool scalar = plot.times_s.size() <= 1;
  PlotSeries initial;
  initial.name = "initial design";
  initial.color = "#7f7f7f";
  initial.dash = "6 3";
  initial.marker = scalar ? MarkerShape::kHollowCircle : MarkerShape::kNone;
  initial.x = plot.times_s;
  initial.y = plot.initial;
  PlotSeries final;
  final.name = "final design";
  final.color = "#1f77b4";
  final.marker = scalar ? MarkerShape::kCircle : MarkerShape::kNone;
  final.x = plot.times_s;
  final.y = plot.final;
  spec.series = {initial, final};
  for (const ResponsePlot::Limit& limit : plot.limits) {
    ReferenceLine line;
    line.y = limit.value;
    line.label = limit.label;
    line.color = "#d62728";
    spec.reference_lines.push_back(line);
  }
  spec.height_px = 260.0;
  return spec;
}

}  // namespace mbopt::report
