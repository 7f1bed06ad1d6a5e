// The server's jobs: it runs each job's optimizer, logs every analysis and
// cycle record to the store, keeps the scheduler supplied with the analyses
// the optimizers ask for, and hands results back to them. It is the one
// place where the store, the scheduler and the optimizers meet; it speaks
// domain types only (the gRPC services translate).
//
// Ordering, per job (under the job's mutex): a batch of results (one or
// more that a worker reported together) is given to the optimizer; its new
// requests are queued (a task is not a record: workers start on them while
// the commit syncs); the results and the records they made it emit are
// committed in one transaction with the job's progress; only then is the
// worker told its results were taken, and the records are published to
// watchers once they are durable (at the default durability, after the
// log-syncing thread has synced the log: the worker does not wait for it).
// So a record is durable before anyone sees it, and a crash at any point is
// repaired by replay (job.h).
//
// Every change of a job's state goes through one function (EnterStateLocked),
// which persists it, logs the event and wakes watchers; a store error on the
// way is logged, never dropped. Results are validated once, by the job's
// intake (jobs::Job::Intake), into the record that is logged and replayed.
// The LP solver of each job and the clock are injected.
//
// Thread-safe. Optimizer work is short (LP solves) and done on the calling
// thread under the job's mutex; the store's commits and the log's syncs
// (on the LogSyncer's thread, log_syncer.h) are the only I/O. Summaries and
// views are built in job_views.cc; admission limits are admission.h's.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "server/jobs/analysis_record.h"
#include "server/jobs/job.h"
#include "server/jobs/job_state.h"
#include "server/jobs/manager/admission.h"
#include "server/jobs/manager/job_view.h"
#include "server/jobs/manager/log_syncer.h"
#include "server/lp/linear_program.h"
#include "server/scheduler/clock.h"
#include "server/scheduler/scheduler.h"
#include "server/store/store.h"
#include "spec/layout.h"
#include "spec/study.h"

namespace mbopt::jobs::manager {

// Turns a stored study (opaque bytes, the service's serialization) into a
// validated study. InvalidArgument naming `source_name` and the field.
using StudyDecoder =
    std::function<absl::StatusOr<spec::Study>(const std::string& study_bytes, const std::string& source_name)>;

struct JobManagerOptions {
  // Called after each cycle record is committed, with the number committed
  // by this manager so far (all jobs). For fault-injection tests.
  std::function<void(std::int64_t records_committed)> after_record_commit;
  // Called by the log's syncing thread before each sync of the job log. For
  // tests that hold records back from watchers.
  std::function<void()> before_log_sync;
  // Makes each job's LP solver (one per job and per resume). Required.
  std::function<std::unique_ptr<lp::LpSolver>()> make_lp_solver;
  // Measures the jobs' running time; not owned. nullptr: a steady clock.
  const scheduler::Clock* clock = nullptr;
  // How many jobs run at once; the others wait (QUEUED) in submission order.
  AdmissionLimits admission;
  // Inspection only (`mbopt status --db` and the like): Start() resumes and
  // admits nothing, a job the database calls running is shown INTERRUPTED
  // (its server is gone: the store's lock proves no other server holds the
  // file), and Submit and Resume are refused. Nothing is written for them.
  bool inspect_only = false;
  // Named in the messages of inspect_only ("mbopt resume JOB --db PATH").
  std::string db_path_for_messages;
  // Spot checks (spot_check.h): the share of analyses, 0 to 1, answered by
  // two workers that must agree bit for bit before the optimizer sees them.
  // 0: none.
  double verify_fraction = 0;
};

// One result from a worker: where it goes, and the candidate record the
// job's intake validates (request_id set; x_scaled and attempts are the
// scheduler's).
struct WorkerReport {
  std::string worker_id;
  std::string holder;  // the name of the reporting call's token ("" without tokens)
  std::string task_id;
  std::string job_id;
  jobs::AnalysisRecord record;
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

  // Validates and starts a study, or queues it (QUEUED) while the running
  // limits are reached (JobManagerOptions::admission). InvalidArgument from
  // the decoder; ResourceExhausted when the owner may not queue one more
  // job. `owner` is the name of who submitted it ("" on a server without
  // tokens).
  // `actor` (here and for Cancel and Resume) says who asked, for the job's
  // event log ("user alice (peer ipv4:...)"); "": nobody is named.
  absl::StatusOr<std::string> Submit(const std::string& study_bytes, const std::string& source_name,
                                     const std::string& owner = "", const std::string& actor = "");
  // The answer for an unknown job: NotFound naming the id. The service
  // gives the same for another user's job, so that ids do not tell which
  // jobs exist.
  static absl::Status NoSuchJob(const std::string& job_id);
  absl::Status InspectOnlyRefusal(const std::string& what) const;
  // Who submitted the job. NotFound naming the id for an unknown job.
  absl::StatusOr<std::string> OwnerOf(const std::string& job_id);

  // NotFound naming the id for an unknown job.
  absl::StatusOr<JobView> Get(const std::string& job_id, std::size_t first_record = 0,
                              JobViewFor view_for = JobViewFor::kReader);
  absl::StatusOr<std::vector<JobSummaryData>> List();
  // The registered workers (`mbopt workers`).
  std::vector<scheduler::WorkerView> Workers() const { return scheduler_->Workers(); }
  // FailedPrecondition when the job has already ended.
  absl::StatusOr<JobSummaryData> Cancel(const std::string& job_id, const std::string& actor = "");
  // Continues an interrupted or cancelled job (replaying its log), or queues
  // it while the running limits are reached; a running or queued job is
  // returned as is. FailedPrecondition for a job that has ended.
  absl::StatusOr<JobSummaryData> Resume(const std::string& job_id, const std::string& actor = "");

  // Waits (real time, at most `max_wait_ms`) until the job's version differs
  // from `version_seen`, then returns its records from `first_record` on
  // (a watcher's view).
  absl::StatusOr<JobView> WaitForChange(const std::string& job_id, std::size_t first_record,
                                        std::int64_t version_seen, std::int64_t max_wait_ms);

  // A worker's result. Returns whether it was taken (false: the task is not
  // outstanding any more, the result is dropped). InvalidArgument for a
  // result that does not fit its task (sizes, ids): the worker gets the
  // error, the attempt counts as failed, the job goes on. Gradients that do
  // not fit (wrong size, non-finite) or that the task did not ask for are
  // not an error: the values are taken without them (the reason is logged
  // with the analysis) and the optimizer uses finite differences for that
  // cycle. NotFound for an unknown job. PermissionDenied for a task never
  // leased to the reporting worker (Scheduler::Complete): nothing is taken.
  // Unavailable after Shutdown.
  absl::StatusOr<bool> ReportResult(WorkerReport report);
  // Several results (a worker's batch), one answer each, in order, as
  // ReportResult would give it. The results of one job are applied to its
  // optimizer together and committed in one transaction with the cycle
  // records they complete (one commit, and one sync, per job and batch).
  std::vector<absl::StatusOr<bool>> ReportResults(std::vector<WorkerReport> reports);

  // A worker could not run a task (not a failure of the analysis).
  absl::Status ReportWorkerError(const std::string& worker_id, const std::string& task_id,
                                 const std::string& reason);

  // Expires overdue leases; tasks that used up their attempts go to their
  // optimizers as failed analyses. Call periodically.
  void ExpireLeases();
  // The worker's connection closed: its tasks are requeued now
  // (Scheduler::WorkerLost), and those out of attempts reported as failed.
  void WorkerLost(const std::string& worker_id);

  // A watch stream opens and ends on the job: while one is open, a job
  // that stops keeps its study and records in memory, so the stream's last
  // views (the final records, then the summary) are not read back from the
  // database. NotFound for an unknown job.
  absl::Status StartWatching(const std::string& job_id);
  void StopWatching(const std::string& job_id);

  // Waits until no cycle record waits for the log's sync (all are
  // published to views). For tests that read a running job's records.
  void WaitForLogSync();

  // Jobs whose study and records are in memory: the running ones (a
  // stopped job keeps only its summary; views read the rest from the
  // database). For tests and the memory benchmark.
  std::size_t ResidentJobs();
  // How many times a stopped job gave up its study and records (a count
  // that only grows): the server returns freed memory to the system when
  // it changes.
  std::int64_t Evictions() const { return evictions_.load(std::memory_order_relaxed); }

  // The stored study of a job (for workers). NotFound for an unknown job.
  absl::StatusOr<std::string> StudyBytes(const std::string& job_id);
  // How many of the job's logged analyses each token holder's workers
  // delivered (`mbopt results`' "computed by"). NotFound for an unknown job.
  absl::StatusOr<std::vector<store::AnalysesByHolder>> ComputedBy(const std::string& job_id);

  // Marks running jobs INTERRUPTED (they resume on the next start), wakes
  // watchers and refuses further results. Idempotent.
  void Shutdown();

 private:
  struct Entry;

  absl::StatusOr<std::shared_ptr<Entry>> Find(const std::string& job_id);
  // Starts queued jobs while the limits allow, oldest first. Called with no
  // lock held, after every call that may have stopped a job.
  void AdmitWaiting();
  // A worker whose answer to a spot check two others contradicted.
  struct Contradicted {
    std::string worker_id;  // full id
    std::string public_id;
    std::string holder;
    std::string job_id;
    std::int64_t request_id = 0;
    std::string agreed_by;  // the public ids of the workers that agree
  };
  // The body of ReportResults (AdmitWaiting and the quarantine of
  // contradicted workers follow it, outside its locks).
  std::vector<absl::StatusOr<bool>> IntakeResults(std::vector<WorkerReport> reports,
                                                  std::vector<Contradicted>* contradicted);
  // The following run under the entry's mutex.
  // How EnterStateLocked records a state: SetJobState, or already stored
  // by the caller in the same transaction as other rows.
  enum class Persist { kSetState, kAlreadyStored };
  // The one place where a job's state changes. Starts or stops the running
  // time, drops the job's tasks when it stops running, persists the state
  // with its event (if `event` is not empty) in one commit, unless the
  // caller's own write stored both (kAlreadyStored: then `event` is empty),
  // and wakes watchers. Returns the store's error; it is also logged.
  absl::Status EnterStateLocked(Entry& entry, jobs::JobState to, std::string message, const std::string& event,
                                const std::string& event_detail, Persist persist = Persist::kSetState);
  // Makes the job's optimizer again (replaying its log) and runs it; `event`
  // names the change in the job's event log.
  absl::Status ResumeLocked(Entry& entry, const std::string& why, const std::string& event = "resumed");
  // Loads the study (decoded and laid out) and the cycle records of the
  // entry's row (row.study must be set); `cycles_status` says whether the
  // cycle log could be read. A study that cannot be decoded leaves study_ok
  // false and the reason in message.
  void LoadContentLocked(Entry& entry, absl::Status* cycles_status);
  // A stopped job gives up its study and records, keeping its summary; a
  // running or watched one is left alone. RestoreLocked reads them back.
  void EvictLocked(Entry& entry);
  // Frees the study, its bytes and the records (EvictLocked without a new
  // summary).
  void DropContentLocked(Entry& entry);
  absl::Status RestoreLocked(Entry& entry);
  // The view of a job whose records may have to be read from the database.
  absl::StatusOr<JobView> RestoredViewLocked(Entry& entry, std::size_t first_record, JobViewFor view_for);
  // Validates a worker's result for the job (the task, the request still
  // pending, the job's intake) and completes its task: the record to
  // deliver; nullopt when it is to be dropped (not outstanding any more);
  // InvalidArgument for a result that does not fit its task.
  // A result held for a spot check sets *held and returns nullopt.
  absl::StatusOr<std::optional<jobs::AnalysisRecord>> TakeResultLocked(Entry& entry, WorkerReport report, bool* held,
                                                                       std::vector<Contradicted>* contradicted);
  // Spot checks (job_spot_checks.cc). A checked analysis' answer: true when
  // it is held until another worker's answer agrees (its task was queued
  // again); false when *record is now the answer to take (two agreed, no
  // other worker could check it, or too many disagreed: a failure), whose
  // task the caller completes. Errors of Scheduler::AskAnotherWorker.
  absl::StatusOr<bool> SpotCheckLocked(Entry& entry, const WorkerReport& report, jobs::AnalysisRecord* record,
                                       std::vector<Contradicted>* contradicted);
  // A checked analysis whose second opinion could not be had (`task` was
  // given up): its held answer is delivered. False when none is held.
  bool TakeHeldAnswerLocked(Entry& entry, const scheduler::FinishedTask& task);
  // Quarantines the workers (Scheduler::Quarantine), drops their held
  // answers, and writes an event to each job concerned and a line to the
  // log. Takes the jobs' locks: called with none held.
  void QuarantineContradicted(const std::vector<Contradicted>& contradicted);
  // Takes back the analyses of the running job that the worker (public id)
  // answered unchecked, with everything logged after the first of them
  // (records, later analyses), and runs the job on from there: what it
  // computes again the other workers answer. Returns how many analyses
  // were taken back (0: none of its unchecked answers here) and the records
  // kept in *kept_records.
  absl::StatusOr<std::int64_t> RecomputeUncheckedLocked(Entry& entry, const std::string& public_id,
                                                        std::size_t* kept_records);
  // What a batch of a job's results (or the records of a replay) makes the
  // job write, in one transaction, and do once that is committed.
  struct Delivery {
    bool needs_commit = false;  // false: nothing was applied, nothing to write
    // Its analyses point into the caller's batch; it carries records (and
    // the job's progress) when it has progress.
    store::JobWrite write;
    std::vector<slp::CycleRecord> records;
    jobs::JobState state = jobs::JobState::kRunning;  // the optimizer's, with records
    std::string message;
  };
  // Applies a batch of the job's results to its optimizer and queues its
  // new requests; returns the write. An error (the optimizer refused a
  // result) has failed the job.
  absl::StatusOr<Delivery> PrepareDeliveryLocked(Entry& entry, const std::vector<jobs::AnalysisRecord>& batch);
  // The write of the optimizer's new records with the job's progress and
  // `analyses`.
  Delivery RecordsDeliveryLocked(Entry& entry, std::vector<slp::CycleRecord> records,
                                 std::vector<const jobs::AnalysisRecord*> analyses);
  // After the delivery's commit: publishes its records (and enters the end
  // state the optimizer reached), or fails the job when `committed` is an
  // error.
  absl::Status FinishDeliveryLocked(Entry& entry, Delivery delivery, const absl::Status& committed);
  // Records committed without a sync (store::JobWrite::defer_sync) wait in
  // the entry until the syncing thread has synced the log; then they are
  // published. PublishUnsyncedLocked publishes them all (after a commit
  // that synced the log anyway); PublishSyncedLocked those committed up to
  // the sync numbered `synced`.
  void PublishUnsyncedLocked(Entry& entry);
  bool PublishSyncedLocked(Entry& entry, std::int64_t synced);
  // Prepare, commit (alone) and finish a batch.
  absl::Status DeliverLocked(Entry& entry, const std::vector<jobs::AnalysisRecord>& batch);
  // Commits the optimizer's new records with the job's progress in one
  // transaction (a replay's records not yet logged).
  absl::Status CommitRecordsLocked(Entry& entry, std::vector<slp::CycleRecord> records);
  void ScheduleLocked(Entry& entry);
  void FailJobLocked(Entry& entry, const std::string& message);
  JobSummaryData SummaryLocked(const Entry& entry) const;
  JobView ViewLocked(const Entry& entry, std::size_t first_record, JobViewFor view_for) const;
  double WallSecondsLocked(const Entry& entry) const;
  void Changed(Entry& entry);
  // The record of a task the scheduler gave up on (attempts used up, or a
  // result that did not fit), delivered as a failed analysis.
  void DeliverGivenUpLocked(Entry& entry, const scheduler::FinishedTask& task);
  void GiveUp(const scheduler::FinishedTask& task);

  store::Store* store_;
  scheduler::Scheduler* scheduler_;
  StudyDecoder decoder_;
  JobManagerOptions options_;
  scheduler::SteadyClock steady_clock_;
  const scheduler::Clock* clock_;

  std::mutex mutex_;  // guards jobs_, shutdown_, records_committed_
  std::map<std::string, std::shared_ptr<Entry>> jobs_;
  bool shutdown_ = false;
  std::int64_t records_committed_ = 0;
  std::atomic<std::int64_t> evictions_{0};

  // Lock order: admit_mutex_, then mutex_ or a job's mutex, then
  // admission_mutex_ (taken last and briefly, by EnterStateLocked too).
  std::mutex admit_mutex_;  // one admission decision at a time (Submit, Resume, AdmitWaiting)
  mutable std::mutex admission_mutex_;  // guards admission_
  Admission admission_;

  // At Durability::kCycles (else null). Last: its thread reads the above.
  std::unique_ptr<LogSyncer> syncer_;
};

}  // namespace mbopt::jobs::manager
