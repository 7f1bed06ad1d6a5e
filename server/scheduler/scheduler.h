// The task queue of the server: analyses waiting for workers, across all
// jobs, and the leases of the ones being worked on.
//
// - Fair between jobs: each task handed out comes from the next job (in job
//   id order, round robin) that has a task waiting, so a job with hundreds of
//   perturbations does not starve a job with one.
// - Leases: a task given to a worker carries a deadline (lease_ms from now on
//   the injected clock); a heartbeat naming the task extends it. When a lease
//   expires (ExpireLeases), the attempt counts as failed and the task is
//   queued again, preferring a worker that has not failed it yet.
// - Retry limit: after max_attempts failed attempts (lease expiries or
//   worker-side errors) the task is given up and returned to the caller, who
//   reports it to the optimizer as a failed analysis. An analysis that itself
//   reports failure is not a failed attempt: the caller completes the task
//   with that result and it is not retried.
// - A result that arrives after its lease expired is still taken if no other
//   attempt of the same analysis has finished first: analyses are
//   deterministic, so any attempt's values are as good as another's.
//
// The scheduler knows nothing of optimizers, gRPC or the database. It is
// thread-safe; AcquireWait blocks (real time) for the long poll of workers.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "server/scheduler/clock.h"

namespace mbopt::scheduler {

struct SchedulerOptions {
  std::int64_t lease_ms = 30'000;
  // How often workers are asked to send heartbeats; well below lease_ms.
  std::int64_t heartbeat_interval_ms = 5'000;
  int max_attempts = 3;
  // A worker not heard from for this long is not counted as a live
  // alternative when choosing who retries a task. 0: 3 * lease_ms.
  std::int64_t worker_silence_ms = 0;
  // Called each time an AcquireWait is about to block (no task on offer, no
  // shutdown), with the scheduler's lock held: the wait begins as soon as it
  // returns, so whatever happens next (Enqueue, Shutdown) meets a blocked
  // long poll. It must not call the scheduler. For tests that need the poll
  // to be waiting, not merely started; empty: nothing is called.
  std::function<void()> on_long_poll_blocks;
  absl::Status Validate() const;
};

// What a worker can run beyond the built-in models (it says so when it
// registers): a task that needs more goes only to a worker that has it.
struct WorkerCapabilities {
  std::vector<std::string> drivers;  // analysis drivers it declares
  std::string fmu_platform;          // FMU binaries it loads; empty: none
};

// What every task of a job needs of its worker; default: any worker.
struct TaskNeeds {
  std::string driver;  // non-empty: a worker declaring this driver
  // A worker that loads FMUs (a non-empty fmu_platform), and when
  // fmu_platforms is not empty (the study carries its FMU, whose
  // binaries/<platform>/ folders were read) one whose platform is among them.
  bool loads_fmus = false;
  std::vector<std::string> fmu_platforms = {};
  bool RunnableBy(const WorkerCapabilities& capabilities) const;
  // "driver \"x\"", for messages; "" when any worker will do.
  std::string Describe() const;
};

// A registered worker as `mbopt workers` shows it.
struct WorkerView {
  std::string public_id;  // "w-<n>"
  std::string name;
  std::string holder;     // the name of the token it registered with; "" without tokens
  int slots = 1;
  WorkerCapabilities capabilities;
  std::int64_t analyses_done = 0;  // results taken from it
  int tasks_held = 0;              // leased to it now
  std::int64_t silent_ms = 0;      // on the scheduler's clock
  bool quarantined = false;        // a spot check caught it: it gets no more tasks
};

// A task as handed to a worker.
struct Task {
  std::string task_id;  // "<job id>/<request id>/<attempt>", unique on the server
  std::string job_id;
  std::int64_t request_id = 0;
  std::vector<double> x_scaled;
  int attempt = 1;                    // 1-based
  std::int64_t lease_deadline_ms = 0; // on the scheduler's clock
  bool want_gradients = false;        // also compute d(values)/d(x_scaled)
};

// A task finished: its result was taken (Complete) or it was given up.
struct FinishedTask {
  std::string job_id;
  std::int64_t request_id = 0;
  std::vector<double> x_scaled;
  int attempts = 0;           // leases handed out for it
  std::string worker_id;      // Complete: who delivered
  std::string failure_reason; // given up: the last attempt's failure
  // Complete: real time from the request's queueing to its result, retries
  // included (a measurement for benchmarks; the injected clock has no part
  // in it).
  double latency_seconds = 0;
};

struct HeartbeatReply {
  bool known = false;                        // false: the worker must register again
  std::vector<std::string> cancelled_task_ids;  // no longer wanted: stop working on them
};

// The part of a worker id that may be shown (in logs, job events and the
// job log): "w-<n>", without the secret part.
std::string PublicWorkerId(std::string_view worker_id);

class Scheduler {
 public:
  // `clock` is not owned and must outlive the scheduler.
  Scheduler(const Clock* clock, SchedulerOptions options);

  const SchedulerOptions& options() const { return options_; }

  // Returns the new worker's id: "w-<n>.<64 random bits in hex>". The
  // random part makes the id a worker's proof of its registration: a holder
  // of the (shared) worker token cannot guess another worker's id, and so
  // cannot answer the tasks leased to it. Only PublicWorkerId(id) goes into
  // messages, events and the job log.
  // `holder`: the name of the token it registered with (per-worker tokens
  // are revoked one by one: WorkerIdsHeldBy finds the workers to drop).
  std::string RegisterWorker(const std::string& name, int slots, WorkerCapabilities capabilities = {},
                             const std::string& holder = "");
  // The (full) ids of the registered workers whose token holder is `holder`.
  std::vector<std::string> WorkerIdsHeldBy(const std::string& holder) const;

  // Every task of `job_id` (queued now or later) goes only to a worker
  // that can run it; DropJob forgets it.
  void SetJobNeeds(const std::string& job_id, TaskNeeds needs);
  // Whether a registered worker can run tasks with `needs`; always true when
  // they need nothing beyond the built-in models.
  bool SomeWorkerCan(const TaskNeeds& needs) const;
  // The drivers the registered workers declare, sorted, each once.
  std::vector<std::string> OfferedDrivers() const;
  // The registered workers, in registration order.
  std::vector<WorkerView> Workers() const;

  // Queues an analysis of `job_id`; `want_gradients` is passed on to the
  // worker with every attempt. A request already queued, leased or finished
  // is ignored (returns false), so callers may offer the optimizer's whole
  // pending list each time.
  bool Enqueue(const std::string& job_id, std::int64_t request_id, std::vector<double> x_scaled,
               bool want_gradients = false);
  // Queues several analyses of `job_id` at once, as Enqueue each, and wakes
  // the waiting workers once all are queued (so that the first to wake sees
  // them all and takes its share, not one). Returns how many were new.
  struct NewTask {
    std::int64_t request_id = 0;
    std::vector<double> x_scaled;
    bool want_gradients = false;
  };
  int EnqueueAll(const std::string& job_id, std::vector<NewTask> tasks);

  // Up to `max_tasks` tasks for `worker_id`, fairly across jobs. A worker
  // may ask for more tasks than it has slots (to run them back to back and
  // report their results together); it gets at most its share, by slots,
  // of the work outstanding (queued and leased), less what it holds, and
  // never fewer than its free slots: a batch does not leave other workers
  // idle. NotFound for an unknown worker (it must register again).
  absl::StatusOr<std::vector<Task>> Acquire(const std::string& worker_id, int max_tasks);
  // As Acquire, but waits up to `wait_ms` (real time) for a task to appear
  // when none is available. Returns early (empty) on Shutdown().
  absl::StatusOr<std::vector<Task>> AcquireWait(const std::string& worker_id, int max_tasks,
                                                std::int64_t wait_ms);

  // The worker delivered the result of `task_id`: the task is finished and
  // the caller hands the result to the optimizer. NotFound when the task is
  // not outstanding any more (finished by another attempt, given up, or its
  // job cancelled): the result must be dropped. PermissionDenied when no
  // attempt of the task was ever leased to `worker_id` (a worker answering
  // another's task): refused, and the task stays as it was.
  absl::StatusOr<FinishedTask> Complete(const std::string& worker_id, const std::string& task_id);

  // Spot checks. The worker answered `task_id`, and its answer is to be
  // checked against another worker's: the lease ends without finishing the
  // task, which is queued again (first in its job's queue) for a worker that
  // has not answered it yet. Its answer stays the caller's to keep. Errors
  // as Complete; a worker that already answered the task cannot Complete it.
  absl::Status AskAnotherWorker(const std::string& worker_id, const std::string& task_id);
  // Whether a live worker other than these (full ids) could take a task.
  bool HasLiveWorkerBesides(const std::set<std::string>& worker_ids) const;
  // The worker gets no more tasks and its results are refused; the tasks
  // it holds are failed attempts (queued again, or given up and returned as
  // WorkerLost does). It stays listed (WorkerView::quarantined). Returns
  // the tasks given up; nullopt for a worker unknown or already quarantined.
  std::optional<std::vector<FinishedTask>> Quarantine(const std::string& worker_id);

  // The worker could not run `task_id` (not a failure of the analysis
  // itself). Returns the task if this used up its attempts (give up: report
  // a failed analysis), nullopt if it was queued again. NotFound as Complete.
  absl::StatusOr<std::optional<FinishedTask>> Fail(const std::string& worker_id,
                                                   const std::string& task_id,
                                                   const std::string& reason);

  HeartbeatReply Heartbeat(const std::string& worker_id, const std::vector<std::string>& task_ids);

  // Handles every lease past its deadline; returns the tasks given up.
  std::vector<FinishedTask> ExpireLeases();

  // The worker's connection closed (its process ended, or the network
  // went): every task leased to it is a failed attempt now, as if its lease
  // had expired, and the worker is forgotten (a live one registers again).
  // Returns the tasks given up. Unknown workers are ignored.
  std::vector<FinishedTask> WorkerLost(const std::string& worker_id);

  bool IsKnownWorker(const std::string& worker_id) const;
  // Waits up to `wait_ms` (real time) for Shutdown(); true once it happened.
  bool WaitForShutdown(std::int64_t wait_ms) const;

  // Forgets every queued and leased task of `job_id` (cancelled or ended).
  void DropJob(const std::string& job_id);

  // Wakes every AcquireWait; later calls do not wait.
  void Shutdown();

  // Counts, for progress displays and tests.
  int QueuedCount() const;
  int LeasedCount() const;

 private:
  struct Entry {
    std::string job_id;
    std::int64_t request_id = 0;
    std::vector<double> x_scaled;
    bool want_gradients = false;
    int attempts = 0;                  // leases handed out
    int failures = 0;                  // failed attempts
    std::set<std::string> failed_workers;
    std::set<std::string> answered_workers;  // spot checks: whose answers are held
    std::string last_failure;
    bool leased = false;
    std::string worker_id;             // while leased
    std::string task_id;               // current attempt's id, while leased
    std::int64_t lease_deadline_ms = 0;
    std::chrono::steady_clock::time_point queued_at;  // first queued (real time)
  };
  using Key = std::pair<std::string, std::int64_t>;  // job id, request id
  struct Worker {
    std::string name;
    std::string holder;
    int slots = 1;
    std::int64_t last_seen_ms = 0;
    WorkerCapabilities capabilities;
    std::int64_t number = 0;         // n of "w-<n>"
    std::int64_t analyses_done = 0;
    bool quarantined = false;
  };

  std::vector<Task> AcquireLocked(const std::string& worker_id, int max_tasks);
  // How many more tasks `worker_id` may hold now (Acquire); may be <= 0.
  int FairShareLocked(const std::string& worker_id) const;
  bool HasOtherLiveWorker(const std::string& worker_id, const std::set<std::string>& excluded) const;
  // The entry of `task_id`'s analysis if `worker_id` may answer it (holds or
  // held one of its leases); NotFound and PermissionDenied as Complete.
  absl::StatusOr<std::map<Key, Entry>::iterator> AnswerableLocked(const std::string& worker_id,
                                                                  const std::string& task_id);
  // Records a failed attempt; returns the finished task if it is given up.
  // The key by value: a caller's may live in the lease this erases.
  std::optional<FinishedTask> FailLocked(Key key, const std::string& reason);
  // Fails every leased attempt for which `lost` holds, with `reason`; sets
  // *requeued when one was queued again. Returns the tasks given up.
  std::vector<FinishedTask> FailLeasesLocked(const std::function<bool(const Entry&)>& lost,
                                             const std::function<std::string(const Entry&)>& reason, bool* requeued);
  void RemoveFromQueue(const Key& key);

  const Clock* clock_;
  const SchedulerOptions options_;
  mutable std::mutex mutex_;
  std::condition_variable task_available_;
  mutable std::condition_variable shutdown_signal_;
  bool shutdown_ = false;
  std::int64_t next_worker_ = 1;
  std::map<std::string, Worker> workers_;
  std::map<std::string, TaskNeeds> job_needs_;         // jobs whose tasks need more than any worker
  std::map<Key, Entry> entries_;                       // queued or leased
  std::set<Key> finished_;                             // never re-queued
  std::map<std::string, std::deque<std::int64_t>> queues_;  // job -> queued request ids
  std::map<std::string, Key> leases_;                  // task id -> entry
  std::string last_served_job_;
};

}  // namespace mbopt::scheduler
