// The history figures of the job report as plot specifications, built from
// the cycle records. The x axis counts cycles: 0 is the initial design (x0
// of cycle 1), k the design accepted in cycle k (which is x0 of cycle k+1).
// Rejected trial points of cycle k are drawn at k as hollow markers.
#pragma once

#include <string>
#include <vector>

#include "client/report/report_data.h"
#include "client/report/plot_axis.h"
#include "client/report/svg_line_plot.h"

namespace mbopt::report {

// Approximation-error thresholds of the move-limit strategy (METHOD.md
// section 3): widen below 0.10, narrow above 0.25, reject above 0.40.
inline constexpr double kErrorWidenBelow = 0.10;
inline constexpr double kErrorNarrowAbove = 0.25;
inline constexpr double kErrorRejectAbove = 0.40;
// A feasible LP whose trial point violates more than this is rejected.
inline constexpr double kViolationRejectAbove = 0.10;

// The colour of series k (10 distinguishable colours, then repeated with a
// different dash pattern: see SeriesDash).
std::string SeriesColor(int k);
std::string SeriesDash(int k);

PlotSpec ObjectivePlot(const ReportData& data);
PlotSpec ViolationPlot(const ReportData& data);
PlotSpec ApproximationErrorPlot(const ReportData& data);
PlotSpec MoveLimitPlot(const ReportData& data);
PlotSpec DesignVariablePlot(const ReportData& data);

// Display name of design variable i: its name, or "x<i+1>" when unknown.
std::string VariableName(const ReportData& data, int i);

}  // namespace mbopt::report
