// The report page's responses for one job: `mbopt-worker eval` runs the
// job's study (its scene inlined) at the initial and at the final design and
// writes every series (--series-out); each objective term's and
// constraint's output becomes a plot of both analyses with the constraint's
// limits. Two analyses per report: cheap next to the job itself.
//
// The same two analyses give the x-y plots (the study's `plots` and
// `mbopt report --plot X:Y`) and every constraint row at the final design,
// from which the page lists the active ones.
#pragma once

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "client/report/report_data.h"
#include "mbopt/v1/service.pb.h"
#include "spec/study.h"

namespace mbopt::client {

// The SLP's convergence tolerance on maxg for `study`, as the server's
// jobs::SlpOptionsFromStudy sets it (a test keeps the two equal): the
// study's own, else the default narrowed to a quarter of the narrowest
// equality band.
double ViolationToleranceOf(const spec::Study& study);

// data->violation_tolerance from the job's study (left at the default
// when the study cannot be read).
void SetViolationTolerance(const v1::GetJobResponse& job, report::ReportData* data);

// `plot_args` are "X:Y" (x and y named like a constraint's output).
// InvalidArgument naming the option and the names that exist when one is
// not of that form or names no signal.
absl::StatusOr<std::vector<spec::XyPlot>> PlotsFromCommandLine(const spec::Study& study,
                                                               const std::vector<std::string>& plot_args);

// Sets data->violation_tolerance, then fills data->responses,
// data->xy_plots (the study's plots, then `extra_plots`) and the final
// design's constraint rows, or data->responses_note saying why there are
// none (no final design yet, the worker program not found, an analysis
// failed). Prints a line on stderr while the analyses run.
// InvalidArgument only for a bad `plot_args` (PlotsFromCommandLine).
absl::Status AddResponsePlots(const v1::GetJobResponse& job, const std::vector<std::string>& plot_args,
                              report::ReportData* data);

}  // namespace mbopt::client
