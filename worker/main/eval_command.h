// `mbopt-worker eval`: runs one analysis of a study from the command line and
// prints the study's values (objective, worst constraint row), per-output
// summaries, the formulation and the counters, as text or as one JSON object.
#pragma once

#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "spec/study.h"

namespace mbopt::worker {

// Exit codes of the eval subcommand.
inline constexpr int kExitOk = 0;
inline constexpr int kExitAnalysisFailed = 1;
inline constexpr int kExitBadInput = 2;

// `args` are the arguments after "eval". Writes results to `out`, errors to
// `err`; returns one of the exit codes above.
int RunEval(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

// Applies one `--set NAME=VALUE` to the design: NAME a design variable
// (VALUE scaled, into `x`) or a scene parameter (VALUE in its own unit,
// appended to `parameter_overrides` in SI). InvalidArgument says why not.
absl::Status ApplyDesignSet(const spec::Study& study, const std::string& assignment, std::vector<double>* x,
                            std::vector<std::pair<int, double>>* parameter_overrides);

// The usage text of the subcommand.
const char* EvalUsage();

}  // namespace mbopt::worker
