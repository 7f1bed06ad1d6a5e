// How the CLI shows jobs: state names, the cycle table of `watch`, the
// summary of `status`, and the result formats of `results` (table, CSV,
// JSON). Pure formatting of the wire messages; no I/O.
#pragma once

#include <string>

#include "mbopt/v1/service.pb.h"

namespace mbopt::client {

// "converged", "max_cycles", "stalled", "failed", "cancelled",
// "interrupted", "running", "queued".
std::string StateName(v1::JobState state);
bool IsTerminal(v1::JobState state);  // the job will not change by itself
// Exit code of a command that reports a job's outcome (see exit_codes.h).
int ExitCodeForState(v1::JobState state);

// The cycle table: one header and one line per CycleRecord (every LP solve,
// rejected attempts included).
std::string CycleTableHeader();
std::string CycleTableRow(const v1::CycleRecord& record);

// Several lines: id, study, state, cycles, analyses, objective, violation,
// design, message. With the job's study, each design line shows the scaled
// variable and the parameter it sets: "x1 = 5  (k1 = 50 lbf/in)"; without
// it, only the parameter value, which is all the summary carries.
std::string SummaryText(const v1::JobSummary& summary, const v1::Study* study = nullptr);
// The line `watch` ends with: the state, cycles (designs, or points of a
// front) and analyses, and the objective where the job has one.
std::string WatchEndLine(const std::string& job_id, const v1::JobSummary& summary);
// One line for `list`.
std::string ListHeader();
std::string ListRow(const v1::JobSummary& summary);
// `mbopt workers`: one row per registered worker.
std::string WorkersHeader();
std::string WorkersRow(const v1::WorkerSummary& worker);
// "computed by:   rack1 (12 analyses), rack2 (3 analyses)\n": the worker
// tokens whose workers delivered the job's analyses; "" when no token did
// (a server without tokens).
std::string ComputedByText(const v1::GetJobResponse& job);

// `results` formats. The JSON is one object: status, cycles, analyses,
// objective, objective_unit, max_violation, design (name -> physical value),
// design_scaled (name -> scaled value), design_parameters (name -> the scene
// parameter it sets), design_units, wall_seconds, message and history (one
// entry per accepted cycle).
std::string ResultsTable(const v1::GetJobResponse& job);
std::string ResultsCsv(const v1::GetJobResponse& job);
// `database`: where the job is kept (mbopt run), written as "database"
// when not empty.
std::string ResultsJson(const v1::GetJobResponse& job, const std::string& database = "");

}  // namespace mbopt::client
