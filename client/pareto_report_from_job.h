// A Pareto front's job (GetJobResponse) as the data of its report page
// (client/report/pareto_report.h), with point `chosen` (1-based; 0: none)
// marked.
#pragma once

#include "client/report/pareto_report.h"
#include "mbopt/v1/service.pb.h"

namespace mbopt::client {

report::ParetoReportData ParetoReportFromJob(const v1::GetJobResponse& job, int chosen);

}  // namespace mbopt::client
