// `mbopt-worker serve --server ADDRESS [--slots N] [--name NAME]`: the
// command-line front of RunWorker (worker_service.h), so that the worker
// executable's main() only dispatches. Options are documented in
// docs/workers.md.
#pragma once

#include <string>
#include <vector>

namespace mbopt::worker {

// `args` are the arguments after "serve" (or all arguments for the
// `mbopt-worker --server ADDRESS` shorthand). Returns the exit code: 0 after
// a clean stop (SIGTERM/SIGINT), 2 for bad arguments.
int ServeMain(const std::vector<std::string>& args);

// The usage text of the serve subcommand.
const char* ServeUsage();

}  // namespace mbopt::worker
