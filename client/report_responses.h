// The report page's responses for one job: `mbopt-worker eval` runs the
// job's study (its scene inlined) at the initial and at the final design and
// writes every series (--series-out); each objective term's and
// constraint's output becomes a plot of both analyses with the constraint's
// limits. Two analyses per report: cheap next to the job itself.
#pragma once

#include "client/report/report_data.h"
#include "mbopt/v1/service.pb.h"

namespace mbopt::client {

// Fills data->responses, or data->responses_note saying why there are none
// (no final design yet, the worker program not found, an analysis failed).
// Prints a line on stderr while the analyses run.
void AddResponsePlots(const v1::GetJobResponse& job, report::ReportData* data);

}  // namespace mbopt::client
