// The plot of one response at the initial and final designs (ResponsePlot):
// time on x, the two analyses as lines, the constraint's limits as
// reference lines.
#pragma once

#include "client/report/report_data.h"
#include "client/report/svg_line_plot.h"

namespace mbopt::report {

PlotSpec ResponsePlotSpec(const ResponsePlot& plot);

}  // namespace mbopt::report
