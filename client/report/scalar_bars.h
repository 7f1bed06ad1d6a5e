// A scalar response (mass, a response of the parameters: one value per
// analysis) as two horizontal bars, initial and final design, each labelled
// with its value, and the constraint's limits as vertical lines: a value is
// compared with a limit, not followed over a time axis. Self-contained SVG,
// text escaped, like svg_line_plot.h.
#pragma once

#include <string>

#include "client/report/report_data.h"

namespace mbopt::report {

// `plot.scalar()` holds; the last value of each design is the one shown.
std::string RenderScalarBarsSvg(const ResponsePlot& plot);

}  // namespace mbopt::report
