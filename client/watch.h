// Following a job: the Watch stream printed as the cycle table, with a
// progress line below it when the output is a terminal. Shared by `watch`,
// `submit --watch` and `run`.
#pragma once

#include <cstdio>
#include <string>

#include "client/connection.h"
#include "mbopt/v1/service.grpc.pb.h"

namespace mbopt::client {

struct WatchOptions {
  std::FILE* table_out = stdout;  // nullptr: no table
  bool progress_line = false;     // redraw a status line (terminals only)
  // The job's study, for a Pareto front's lines (its second objective's
  // name, unit and sign); null: asked of the server when the first point
  // arrives.
  const v1::Study* study = nullptr;
};

struct WatchOutcome {
  bool ok = false;              // the stream ended normally
  bool interrupted = false;     // Ctrl-C or SIGTERM arrived
  v1::JobSummary summary;       // the last summary received
  RpcFailure failure;           // when !ok && !interrupted
};

WatchOutcome WatchJob(v1::JobService::Stub& job_service, const std::string& address,
                      const std::string& job_id, const WatchOptions& options);

}  // namespace mbopt::client
