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
// design, message.
std::string SummaryText(const v1::JobSummary& summary);
// One line for `list`.
std::string ListHeader();
std::string ListRow(const v1::JobSummary& summary);

// `results` formats. The JSON is one object: status, cycles, analyses,
// objective, objective_unit, max_violation, design (name -> physical value),
// design_units, wall_seconds, message and history (one entry per accepted
// cycle).
std::string ResultsTable(const v1::GetJobResponse& job);
std::string ResultsCsv(const v1::GetJobResponse& job);
std::string ResultsJson(const v1::GetJobResponse& job);

}  // namespace mbopt::client
