// The server's jobs: it runs each job's optimizer, logs every analysis and
// cycle record to the store, keeps the scheduler supplied with the analyses
// the optimizers ask for, and hands results back to them. It is the one
// place where the store, the scheduler and the optimizers meet; it speaks
// domain types only (the gRPC services translate).
//
// Ordering, per job (under the job's mutex): a result is committed to the
// store, then given to the optimizer; the records it emits are committed in
// one transaction with the job's progress, then published to watchers, then
// the optimizer's new requests are queued. So a record is durable before
// anyone sees it, and a crash at any point is repaired by replay (job.h).
//
// Thread-safe. Optimizer work is short (LP solves) and done on the calling
// thread under the job's mutex; the store's commits are the only I/O.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/jobs/job.h"
#include "server/jobs/job_state.h"
#include "server/scheduler/scheduler.h"
#include "server/store/store.h"
#include "spec/layout.h"
#include "spec/study.h"

namespace mbopt::service {

// Turns a stored study (opaque bytes, the service's serialization) into a
// validated study. InvalidArgument naming `source_name` and the field.
using StudyDecoder =
    std::function<absl::StatusOr<spec::Study>(const std::string& study_bytes, const std::string& source_name)>;

struct JobManagerOptions {
  // Called after each cycle record is committed, with the number committed
  // by this manager so far (all jobs). For fault-injection tests.
  std::function<void(std::int64_t records_committed)> after_record_commit;
};

struct JobSummaryData {
  std::string job_id;
  std::string study_name;
  jobs::JobState state = jobs::JobState::kQueued;
  int cycles = 0;
  std::int64_t analyses = 0;
  double objective = 0;           // in objective_unit
  std::string objective_unit;
  double max_violation = 0;       // normalized, > 0 violated
  std::vector<std::string> design_names;
  std::vector<double> design;     // physical: scale * x, parameter units
  std::vector<std::string> design_units;
  double wall_seconds = 0;
  std::string message;
  std::int64_t created_unix_ms = 0;
  int max_cycles = 0;
};

// What a client needs to show a job's records with names and units.
struct JobView {
  JobSummaryData summary;
  std::vector<slp::CycleRecord> records;  // from the requested index on
  std::size_t first_record = 0;           // index of records[0] in the job's log
  std::int64_t version = 0;               // changes with every record or state change
  bool ended = false;                     // the job is not running (nothing more will come)
  std::vector<std::string> row_names;     // constraint rows, for worst_* indices
  std::vector<double> variable_scales;    // physical = scale * x
  std::string study_bytes;
};

// One result from a worker, in domain terms.
struct WorkerResult {
  std::string worker_id;
  std::string task_id;
  std::string job_id;
  std::int64_t request_id = 0;
  bool ok = false;
  std::string failure_reason;
  std::vector<double> objective_terms;
  std::vector<double> constraint_values;
  // When the task wanted gradients: row-major d(value)/d(x_scaled)
  // (server/jobs/analysis_gradients.h), or both empty and the reason.
  std::vector<double> objective_gradients;
  std::vector<double> constraint_gradients;
  std::string gradients_unavailable;
  double wall_seconds = 0;
  store::AnalysisCounters counters;
};

class JobManager {
 public:
  // `store` and `scheduler` are not owned and must outlive the manager.
  JobManager(store::Store* store, scheduler::Scheduler* scheduler, StudyDecoder decoder,
             JobManagerOptions options = {});
  ~JobManager();

  // Loads every job of the store and resumes those that were running
  // (the server crashed) or interrupted (it was stopped). A job whose replay
  // fails is marked FAILED with the reason; the others go on.
  absl::Status Start();

  // Validates and starts a study. InvalidArgument from the decoder.
  absl::StatusOr<std::string> Submit(const std::string& study_bytes, const std::string& source_name);

  // NotFound naming the id for an unknown job.
  absl::StatusOr<JobView> Get(const std::string& job_id, std::size_t first_record = 0);
  absl::StatusOr<std::vector<JobSummaryData>> List();
  // FailedPrecondition when the job has already ended.
  absl::StatusOr<JobSummaryData> Cancel(const std::string& job_id);
  // Continues an interrupted or cancelled job (replaying its log); a running
  // job is returned as is. FailedPrecondition for a job that has ended.
  absl::StatusOr<JobSummaryData> Resume(const std::string& job_id);

  // Waits (real time, at most `max_wait_ms`) until the job's version differs
  // from `version_seen`, then returns its records from `first_record` on.
  absl::StatusOr<JobView> WaitForChange(const std::string& job_id, std::size_t first_record,
                                        std::int64_t version_seen, std::int64_t max_wait_ms);

  // A worker's result. Returns whether it was taken (false: the task is not
  // outstanding any more, the result is dropped). InvalidArgument for a
  // result that does not fit its task (sizes, ids): the worker gets the
  // error, the attempt counts as failed, the job goes on. Gradients that do
  // not fit (wrong size, non-finite) or that the task did not ask for are
  // not an error: the values are taken without them (the reason is logged
  // with the analysis) and the optimizer uses finite differences for that
  // cycle. NotFound for an unknown job. Unavailable after Shutdown.
  absl::StatusOr<bool> ReportResult(const WorkerResult& result);

  // A worker could not run a task (not a failure of the analysis).
  absl::Status ReportWorkerError(const std::string& worker_id, const std::string& task_id,
                                 const std::string& reason);

  // Expires overdue leases; tasks that used up their attempts go to their
  // optimizers as failed analyses. Call periodically.
  void ExpireLeases();

  // The stored study of a job (for workers). NotFound for an unknown job.
  absl::StatusOr<std::string> StudyBytes(const std::string& job_id);

  // Marks running jobs INTERRUPTED (they resume on the next start), wakes
  // watchers and refuses further results. Idempotent.
  void Shutdown();

 private:
  struct Entry;

  absl::StatusOr<std::shared_ptr<Entry>> Find(const std::string& job_id);
  // The following run under the entry's mutex.
  absl::Status ResumeLocked(Entry& entry, const std::string& why);
  absl::Status DeliverLocked(Entry& entry, const store::AnalysisRow& row);
  absl::Status CommitRecordsLocked(Entry& entry, std::vector<slp::CycleRecord> records);
  void ScheduleLocked(Entry& entry);
  void FinishIfDoneLocked(Entry& entry);
  void FailJobLocked(Entry& entry, const std::string& message);
  JobSummaryData SummaryLocked(const Entry& entry) const;
  JobView ViewLocked(const Entry& entry, std::size_t first_record) const;
  double WallSecondsLocked(const Entry& entry) const;
  void Changed(Entry& entry);
  void GiveUp(const scheduler::FinishedTask& task);

  store::Store* store_;
  scheduler::Scheduler* scheduler_;
  StudyDecoder decoder_;
  JobManagerOptions options_;

  std::mutex mutex_;  // guards jobs_, shutdown_, records_committed_
  std::map<std::string, std::shared_ptr<Entry>> jobs_;
  bool shutdown_ = false;
  std::int64_t records_committed_ = 0;
};

}  // namespace mbopt::service
