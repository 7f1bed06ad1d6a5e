// The worker process' connection to an mbopt server: register, long-poll for
// tasks, evaluate them (task_evaluator.h) on `slots` threads, report results,
// and heartbeat so the server extends the leases of tasks in progress and can
// tell the worker which tasks to drop. When the server goes away the worker
// keeps trying to reconnect, with capped exponential backoff, until it is
// stopped; a task whose result cannot be delivered is simply lost (its lease
// expires and the server hands it to another worker).
//
// Threads: one long-polling thread (the caller's), one per slot, one for
// heartbeats. A task the server says is cancelled (its job was cancelled)
// is dropped from the queue; if it is running, its analysis' cancel flag is
// raised, the engine stops at its next budget check (a `cancelled` failure)
// and the result is dropped.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "common/secure_channel/client_security.h"
#include "worker/service/backoff.h"
#include "worker/service/stop_signal.h"
#include "worker/external/scene_analyzer.h"

namespace mbopt::worker {

// The largest WorkerOptions::batch (the server hands out at most this many
// tasks per call).
inline constexpr int kMaxBatch = 64;

struct WorkerOptions {
  std::string server_address;  // host:port
  // TLS and token (common/secure_channel/client_security.h).
  secure_channel::ClientSecurity security;
  int slots = 1;               // analyses at once
  // The most tasks in hand (queued here or running) when asking for more,
  // at least `slots`: tasks handed out together run back to back and their
  // results go back in one call (one round trip and one commit for all).
  // The server caps it at the worker's share of the work outstanding.
  int batch = kMaxBatch;
  std::string name;            // shown on the server; empty: host:pid
  // Long-poll length of AcquireTasks.
  int acquire_wait_ms = 5000;
  BackoffOptions backoff;
  // Testing only: raise SIGKILL on this process right after receiving the
  // N-th task, before evaluating or reporting it (0: never). Recovery tests
  // use it to lose a worker in the middle of a cycle.
  int die_after_tasks = 0;
  // Testing and benchmarks only: hold each result this long (ms) before
  // reporting it, as a slower analysis would; the values are unchanged.
  // The multi-host test uses it to cut links in the middle of a job.
  int task_delay_ms = 0;
  bool verbose = false;  // a line on stderr per task
  // The analysis drivers this worker offers (--drivers) and where their
  // analyses run; null: none. Outlives the worker.
  const external::ExternalWorkerSettings* external = nullptr;
};

// Runs until `stop` is requested; then lets running analyses finish, reports
// their results if the server is there, and returns OK. InvalidArgument for
// bad options. PermissionDenied when the server refuses the worker's token
// (at any time), or when the first connection fails for a reason that is
// the worker's configuration (a certificate it does not trust, a port
// without TLS, ...): a misconfigured worker stops at once instead of
// retrying forever. Once registered, a lost server is waited for.
absl::Status RunWorker(const WorkerOptions& options, StopSignal& stop);

}  // namespace mbopt::worker
