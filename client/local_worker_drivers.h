// The --drivers FILE and --keep-runs of the commands that start local
// workers (`mbopt run`, `mbopt resume --db`), as the workers' arguments.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/args.h"

namespace mbopt::client {

// The drivers file is checked here (`mbopt-worker drivers FILE`), before
// anything starts: a worker that refused it would only say so in its log.
// Empty without --drivers; InvalidArgument for --keep-runs alone or a bad file.
absl::StatusOr<std::vector<std::string>> LocalWorkerDriverArgs(const ParsedArgs& parsed,
                                                               const std::string& worker_binary);

// " --drivers FILE [--keep-runs]" to repeat them in a printed command, or "".
std::string DriverArgsText(const std::vector<std::string>& worker_args);

}  // namespace mbopt::client
