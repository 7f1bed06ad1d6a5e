// Builds the report page's data from the server's GetJob answer: summary,
// cycle records and the study (for variable scales and bounds).
#pragma once

#include <string>

#include "client/report/report_data.h"
#include "mbopt/v1/service.pb.h"

namespace mbopt::report {

// Never fails: a job without a study gets variables without bounds, and
// fields the server left empty stay empty on the page.
ReportData ReportDataFromJob(const v1::GetJobResponse& job);

// The state as the CLI and the page print it: "converged", "max_cycles", ...
std::string JobStateName(v1::JobState state);

}  // namespace mbopt::report
