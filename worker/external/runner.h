// One analysis through a declared driver: a fresh folder, the driver's files
// copied in, the input template filled with the design's values, the command
// run in a process group of its own with a time limit, the results read, the
// folder removed.
//
// What the runner guarantees: numbers reach the driver only as the runner
// formats them (%.17g); nothing the driver started in its process group
// outlives the analysis (the group is killed after the driver ends, and at
// the time limit with SIGTERM, then SIGKILL after a grace period); the
// folder is `<work_directory>/<analysis_id>-<driver>`, mode 0700, and is
// removed afterwards unless `keep_run_folder`; if this process is killed
// outright (SIGKILL) during the analysis, a guard process kills the group
// (group_guard.h). A process that leaves the group (setsid, setpgid) escapes
// the kill: containing those needs cgroups, which the runner does not use.
//
// To reap the driver's orphaned children the runner makes this process a
// child subreaper (prctl PR_SET_CHILD_SUBREAPER): descendants of the driver
// whose parents exit become this process' children, and the runner reaps
// those of the driver's process group.
//
// Failure kinds (spec/analysis_outcome.h), the closest of the vocabulary:
//   time limit reached                         -> time_limit
//   exit code not a success code, killed by a
//   signal, failure marker found, results file
//   missing or malformed                       -> invalid_model (the driver
//                                                 could not analyse this design)
//   a non-finite number in the results         -> non_finite_value
// Errors of the caller or the machine (a value for an undeclared parameter,
// a work directory that cannot be written, a command that cannot be
// started) are a Status, not an analysis failure.
#pragma once

#include <filesystem>
#include <map>
#include <string>

#include "absl/status/statusor.h"
#include "spec/analysis_outcome.h"
#include "worker/external/driver.h"
#include "worker/external/results.h"

namespace mbopt::external {

struct RunOptions {
  std::string analysis_id;  // letters, digits, '_', '-', '.'; part of the folder's name
  std::filesystem::path work_directory;  // created (0700) when missing
  bool keep_run_folder = false;
  // Between SIGTERM and SIGKILL at the time limit.
  double kill_grace_s = 2.0;
  // The last lines of the driver's stderr quoted in a failure's reason.
  int stderr_tail_lines = 10;
};

struct ExternalOutcome {
  spec::AnalysisFailure failure;  // ok, or why the analysis failed
  ExternalResults results;        // read when ok
  int exit_code = -1;             // -1 when killed by a signal or not waited for
  int term_signal = 0;            // the signal that ended the driver, 0 if none
  double wall_seconds = 0.0;
  std::filesystem::path run_folder;
  // Set when the folder could not be removed (the analysis' result stands).
  std::string cleanup_problem;
};

// `values` holds one value per declared parameter, and no other name.
absl::StatusOr<ExternalOutcome> RunExternalAnalysis(const DriverDeclaration& driver,
                                                    const std::map<std::string, double>& values,
                                                    const RunOptions& options);

}  // namespace mbopt::external
