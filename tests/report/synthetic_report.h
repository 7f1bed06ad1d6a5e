// Report data for tests, shaped like the vehicle-suspension run of the 1994
// report (METHOD.md 4.1: objective history 333 ... 252 in/s^2, x1..x3 end on
// their lower bounds, x6 on its upper bound), with two rejected trial points
// added: one for a large approximation error (cycle 2) and one whose
// analysis failed (cycle 5, NaN values). The study name holds < & " to
// exercise escaping.
#pragma once

#include "client/report/report_data.h"

namespace mbopt::report::testing {

inline constexpr char kSyntheticStudyName[] = "vehicle <suspension> & \"seat\"";

ReportData SyntheticVehicleReport();

}  // namespace mbopt::report::testing
