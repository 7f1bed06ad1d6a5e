// A Pareto front's job (GetJobResponse) as the data of its report page
// (client/report/pareto_report.h), with point `chosen` (1-based; 0: none)
// marked.
#pragma once

#include "client/report/pareto_report.h"
#include "mbopt/v1/service.pb.h"

namespace mbopt::client {

report::ParetoReportData ParetoReportFromJob(const v1::GetJobResponse& job, int chosen);

// The chosen point's (data->chosen) run's cycle history, as a single job's
// records (ParetoReportFromJob calls it when a point is chosen); or
// data->chosen_history_note saying why there is none.
void AddChosenPointHistory(const v1::GetJobResponse& job, report::ParetoReportData* data);

// The chosen point's (data->chosen) responses: its design analysed as a
// single job's final design is (client/report_responses.h, two runs of
// `mbopt-worker eval`), each plot naming the point; or
// data->chosen_responses_note saying why there are none (the point has no
// design, the worker program is not found, an analysis failed).
void AddChosenPointResponses(const v1::GetJobResponse& job, report::ParetoReportData* data);

}  // namespace mbopt::client
