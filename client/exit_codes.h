// Exit codes of the `mbopt` command, as documented in docs/cli.md. Scripts
// rely on them: keep the numbers stable.
#pragma once

namespace mbopt::client {

enum ExitCode : int {
  kExitOk = 0,            // command done; for job outcomes: converged
  kExitNotConverged = 1,  // the job ended without converging (max cycles,
                          // stalled, cancelled, interrupted)
  kExitBadInput = 2,      // usage error, invalid study file, unknown job id
  kExitUnreachable = 3,   // no server at the address, or it failed mid-call
  kExitJobFailed = 4,     // the job failed (e.g. its first design cannot be analysed)
  kExitDenied = 5,        // the server refused: no token, a wrong one, or
                          // not the caller's job
  kExitInterrupted = 130, // Ctrl-C (128 + SIGINT), after cleaning up
};

}  // namespace mbopt::client
