// The plots of the responses at the initial and final designs: a response
// over time (ResponsePlot) with the constraint's limits drawn over the
// instants they apply to, and one signal against another (XyPlot). A
// scalar response is drawn as bars instead (scalar_bars.h).
#pragma once

#include "client/report/report_data.h"
#include "client/report/svg_line_plot.h"

namespace mbopt::report {

// Time on x, the two analyses as lines, each limit as a reference line over
// its window, or a marked bar at its one instant. Not for a scalar plot.
PlotSpec ResponsePlotSpec(const ResponsePlot& plot);

// x against y at both designs, lines through the grid's instants in order,
// with a marker where each curve starts (t = 0).
PlotSpec XyPlotSpec(const XyPlot& plot);

}  // namespace mbopt::report
