// The tables of the job report page (HTML fragments, text escaped): the
// final design against its bounds, the active constraints, and one row per
// LP solve.
#pragma once

#include <string>
#include <vector>

#include "client/report/report_data.h"

namespace mbopt::report {

enum class BoundFlag { kNone, kAtLower, kAtUpper, kUnknown };

// A variable counts as on a bound when its scaled value is within this
// fraction of its range from it: the LP puts x* on a bound up to its own
// tolerance (~1e-9 scaled), and the physical value went through one
// multiplication by the scale.
inline constexpr double kBoundRelativeTolerance = 1e-6;

// Where `physical_value` lies relative to the bounds of `variable`
// (kUnknown without bounds or with a zero scale or a non-finite value).
BoundFlag DesignBoundFlag(const ReportVariable& variable, double physical_value);

// The final design in physical units, one value per variable: the summary's
// design when complete, else the last accepted trial point, else x0 of the
// first record; empty when nothing is known.
std::vector<double> FinalDesignPhysical(const ReportData& data);

std::string FinalDesignTableHtml(const ReportData& data);
std::string ActiveConstraintsHtml(const ReportData& data);
std::string CycleTableHtml(const ReportData& data);

}  // namespace mbopt::report
