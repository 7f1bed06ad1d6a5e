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

// The cycle record whose trial point x* is the final design (that of the
// page's header, FinalDesignPhysical): its worst row and maxg describe that
// design. Among several (a design revisited) the one whose maxg is the
// header's, else the last. nullptr when no record has it, e.g. when the
// final design is the initial one.
const ReportCycle* RecordOfFinalDesign(const ReportData& data);

// Two designs are the same when every value agrees to this share of its
// magnitude: the header's design is scale * x of a record's x*, one
// rounding away.
inline constexpr double kSameDesignRelativeTolerance = 1e-9;

// What a normalized constraint value means for the page: " (violated)"
// above the job's violation tolerance, " (within the tolerance T)" in
// (0, T], where a converged design may end, and "" when met or unknown.
std::string ViolationMark(const ReportData& data, double normalized_value);

std::string FinalDesignTableHtml(const ReportData& data);
std::string ActiveConstraintsHtml(const ReportData& data);
std::string CycleTableHtml(const ReportData& data);

}  // namespace mbopt::report
