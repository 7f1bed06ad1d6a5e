// How the CLI shows a design set's job (a sweep or sample, docs/study.md):
// one row per design with its variables, objective, the largest normalized
// value of each constraint and the failure kind of a failed analysis, as a
// plain table, CSV or JSON (`mbopt results`, `mbopt run`), and the row the
// watch prints as each design's record arrives. Pure formatting; no I/O.
#pragma once

#include <string>

#include "mbopt/v1/service.pb.h"

namespace mbopt::client {

// The job analyses a design set (its study has a sweep or sample).
bool IsDesignSetJob(const v1::GetJobResponse& job);

// The watch's lines: "design" (1-based index), F, maxg, "ok" or the
// failure kind, then the design's variables (physical values).
std::string DesignWatchHeader();
std::string DesignWatchRow(const v1::CycleRecord& record);

// The summary, then one row per design analysed so far. Columns: design,
// each variable (physical, in its parameter's unit), objective, max_violation,
// one column per study constraint (its largest (g - c) / scale; > 0
// violated), status (ok or the failure kind); failed values are empty
// (CSV), "-" (table) or null (JSON).
std::string DesignSetTable(const v1::GetJobResponse& job);
std::string DesignSetCsv(const v1::GetJobResponse& job);
// One object: job_id, database (when not empty), study, status, form
// ("sweep" or "sample"), designs_total, designs_done, analyses, the
// objective's unit, the best design's objective and max_violation,
// variables (name, parameter, unit, scale), constraints (names), failed
// analyses by kind, and `designs`: per design index, design (name ->
// physical), design_scaled, objective, max_violation, constraints (name ->
// value), status, failure_reason.
std::string DesignSetJson(const v1::GetJobResponse& job, const std::string& database = "");

}  // namespace mbopt::client
