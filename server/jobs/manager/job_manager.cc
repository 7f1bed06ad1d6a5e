#include "server/jobs/manager/job_manager.h"

#include <algorithm>
#include <chrono>
#include <deque>
#include <iostream>
#include <random>
#include <utility>
#include <variant>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_format.h"
#include "common/check.h"
#include "common/status_macros.h"
#include "server/jobs/job_result.h"
#include "server/jobs/problem_from_study.h"
#include "server/jobs/record_codec.h"
#include "server/jobs/manager/job_entry.h"
#include "server/jobs/manager/spot_check.h"
#include "spec/layout.h"

namespace mbopt::jobs::manager {

using jobs::JobState;

namespace {

// "; by <actor>" for an event's detail, or "" when nobody is named.
std::string ByActor(const std::string& actor) { return actor.empty() ? "" : absl::StrCat("; by ", actor); }

void LogError(const std::string& job_id, const absl::Status& status) {
  std::cerr << "mbopt-server: job " << job_id << ": " << status << std::endl;
}

// "job-" and 12 hex digits from the system's random source.
std::string RandomJobId() {
  std::random_device device;
  const std::uint64_t bits = (static_cast<std::uint64_t>(device()) << 32) ^ device();
  return absl::StrFormat("job-%012x", bits & 0xffffffffffffULL);
}

}  // namespace

JobManager::JobManager(store::Store* store, scheduler::Scheduler* scheduler, StudyDecoder decoder,
                       JobManagerOptions options)
    : store_(store),
      scheduler_(scheduler),
      decoder_(std::move(decoder)),
      options_(std::move(options)),
      clock_(options_.clock != nullptr ? options_.clock : &steady_clock_),
      admission_(options_.admission) {
  if (store_->durability() == store::Durability::kCycles) {
    syncer_ = std::make_unique<LogSyncer>(
        [this] { return store_->SyncLog(); },
        [this](const std::string& job_id, std::int64_t synced) {
          absl::StatusOr<std::shared_ptr<Entry>> entry = Find(job_id);
          if (!entry.ok()) return true;  // gone: nothing of it waits
          std::lock_guard<std::mutex> entry_lock((*entry)->mutex);
          return PublishSyncedLocked(**entry, synced);
        },
        options_.before_log_sync);
  }
}

// The syncing thread publishes into the entries: it stops first.
JobManager::~JobManager() { syncer_.reset(); }

void JobManager::WaitForLogSync() {
  if (syncer_ != nullptr) syncer_->WaitUntilIdle();
}

void JobManager::PublishUnsyncedLocked(Entry& entry) {
  PublishSyncedLocked(entry, std::numeric_limits<std::int64_t>::max());
}

bool JobManager::PublishSyncedLocked(Entry& entry, std::int64_t synced) {
  bool published = false;
  while (!entry.unsynced.empty() && entry.unsynced.front().first <= synced) {
    for (slp::CycleRecord& r : entry.unsynced.front().second) entry.records.push_back(std::move(r));
    entry.unsynced.pop_front();
    published = true;
  }
  if (published) Changed(entry);
  return entry.unsynced.empty();
}

absl::StatusOr<std::shared_ptr<JobManager::Entry>> JobManager::Find(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = jobs_.find(job_id);
  if (it == jobs_.end()) return NoSuchJob(job_id);
  return it->second;
}

void JobManager::Changed(Entry& entry) {
  entry.version += 1;
  entry.changed.notify_all();
}

absl::Status JobManager::EnterStateLocked(Entry& entry, JobState to, std::string message, const std::string& event,
                                          const std::string& event_detail, Persist persist) {
  const std::string& id = entry.row.id;
  if (entry.state != to) {
    std::lock_guard<std::mutex> admission_lock(admission_mutex_);
    if (entry.state == JobState::kRunning) admission_.Stopped(entry.row.owner);
    if (to == JobState::kRunning) admission_.Started(entry.row.owner);
    if (entry.state == JobState::kQueued) admission_.Remove(id);
  }
  if (to == JobState::kRunning) {
    if (!entry.timing) {
      entry.timing = true;
      entry.run_started_ms = clock_->NowMs();
    }
  } else {
    if (entry.timing) entry.wall_before_s = WallSecondsLocked(entry);
    entry.timing = false;
    scheduler_->DropJob(id);
    if (!Running(to) && entry.job != nullptr) {
      // A stopped job keeps its counts and failures for its summary; the
      // optimizer's state (linearization, LP, buffered results) is released
      // here and the study and records by EvictLocked below, so a server's
      // memory does not grow with every finished job. A resume rebuilds
      // them from the log.
      entry.row.cycles = entry.job->cycles_completed();
      entry.row.analyses = entry.job->analyses_used();
      entry.failed_analyses_by_kind.clear();
      for (const auto& [kind, count] : entry.job->failures_by_kind()) {
        entry.failed_analyses_by_kind[spec::FailureKindName(kind)] = count;
      }
      entry.job.reset();
    }
  }
  entry.state = to;
  entry.message = std::move(message);
  absl::Status status;
  if (persist == Persist::kSetState) {
    // The state and its event in one commit: one sync, not two.
    status = store_->SetJobState(id, jobs::JobStateName(to), entry.message,
                                 event.empty() ? std::nullopt : std::optional(store::NewEvent{event, event_detail}));
    if (!status.ok()) LogError(id, status);
  }
  // The state's commit synced the log (or the level never syncs): records
  // still waiting for a sync are durable now, and come before the state.
  PublishUnsyncedLocked(entry);
  if (!Running(to)) EvictLocked(entry);
  Changed(entry);
  return status;
}

void JobManager::EvictLocked(Entry& entry) {
  if (!entry.resident || Running(entry.state) || entry.job != nullptr || entry.watchers > 0) return;
  entry.stopped_summary = SummaryLocked(entry);
  DropContentLocked(entry);
  evictions_.fetch_add(1, std::memory_order_relaxed);
}

void JobManager::DropContentLocked(Entry& entry) {
  std::vector<slp::CycleRecord>().swap(entry.records);
  entry.study = std::make_shared<const spec::Study>();
  entry.layout.reset();  // its rows' names are most of a job's memory
  std::string().swap(entry.row.study);
  entry.resident = false;
}

void JobManager::LoadContentLocked(Entry& entry, absl::Status* cycles_status) {
  entry.study_ok = false;
  absl::StatusOr<spec::Study> study = decoder_(entry.row.study, entry.row.source_name);
  if (study.ok()) {
    // A study this build cannot lay out is known before a resume is tried;
    // the layout serves the views (row names) while the job is resident.
    absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(*study);
    if (layout.ok()) {
      entry.study = std::make_shared<const spec::Study>(*std::move(study));
      entry.layout = std::make_shared<const spec::StudyLayout>(*std::move(layout));
      entry.study_ok = true;
    } else {
      entry.message = std::string(layout.status().message());
    }
  } else {
    entry.message = std::string(study.status().message());
  }
  entry.records.clear();
  absl::StatusOr<std::vector<store::CycleRow>> cycles = store_->LoadCycles(entry.row.id);
  if (cycles.ok()) {
    for (const store::CycleRow& c : *cycles) {
      absl::StatusOr<slp::CycleRecord> record = jobs::DecodeCycleRecord(c.record);
      if (!record.ok()) {
        cycles = record.status();
        break;
      }
      entry.records.push_back(*std::move(record));
    }
  }
  *cycles_status = cycles.status();
  entry.resident = true;
}

absl::Status JobManager::RestoreLocked(Entry& entry) {
  if (entry.resident) return absl::OkStatus();
  MBOPT_ASSIGN_OR_RETURN(store::JobRow row, store_->GetJob(entry.row.id));
  entry.row.study = std::move(row.study);
  // A stored message (why it failed) stays what the summary says.
  const std::string message = entry.message;
  absl::Status cycles;
  LoadContentLocked(entry, &cycles);
  entry.message = message;
  if (!cycles.ok()) {
    DropContentLocked(entry);  // the summary kept is the one from before
    return absl::DataLossError(absl::StrCat("job '", entry.row.id, "': cannot read the cycle log: ", cycles.message()));
  }
  return absl::OkStatus();
}

absl::Status JobManager::Start() {
  MBOPT_ASSIGN_OR_RETURN(std::vector<store::JobRow> rows, store_->ListJobs());
  for (store::JobRow& row : rows) {
    auto entry = std::make_shared<Entry>();
    std::lock_guard<std::mutex> lock(entry->mutex);
    const std::string id = row.id;
    const std::optional<JobState> state = jobs::ParseJobState(row.state);
    entry->state = state.value_or(JobState::kFailed);
    entry->message = state ? row.message : absl::StrCat("unknown state '", row.state, "' in the database");
    entry->wall_before_s = row.wall_seconds;
    entry->row = std::move(row);
    absl::Status cycles;
    LoadContentLocked(*entry, &cycles);
    {
      std::lock_guard<std::mutex> jobs_lock(mutex_);
      jobs_[id] = entry;
    }
    if (!cycles.ok()) {
      FailJobLocked(*entry, absl::StrCat("cannot read the cycle log: ", cycles.message()));
      continue;
    }
    if (entry->state == JobState::kQueued) {
      if (!entry->study_ok) {
        FailJobLocked(*entry, absl::StrCat("cannot start: the stored study is invalid: ", entry->message));
        continue;
      }
      std::lock_guard<std::mutex> admission_lock(admission_mutex_);
      admission_.Enqueue(entry->row.seq, id, entry->row.owner);
      continue;
    }
    if (options_.inspect_only) {
      if (Running(entry->state) || entry->state == JobState::kInterrupted) {
        // In memory only: the next real server resumes it as it finds it.
        entry->state = JobState::kInterrupted;
        // An external scene's analyses need workers that declare its driver.
        const std::string driver = entry->study_ok && entry->study ? NeedsOf(*entry->study).driver : "";
        entry->message = absl::StrCat("interrupted (server not running); `mbopt resume ", id, " --db ",
                                      options_.db_path_for_messages,
                                      driver.empty() ? "" : " --drivers FILE", "` continues it",
                                      driver.empty() ? "" : absl::StrCat(" (FILE declaring driver '", driver, "')"));
      }
      EvictLocked(*entry);
      continue;
    }
    if (entry->state == JobState::kRunning) {
      // It was admitted before the server ended: it counts as running.
      std::lock_guard<std::mutex> admission_lock(admission_mutex_);
      admission_.Started(entry->row.owner);
    }
    if (Running(entry->state) || entry->state == JobState::kInterrupted) {
      const std::string why = entry->state == JobState::kInterrupted ? "the server was stopped"
                                                                     : "the server ended without stopping the job";
      absl::Status resumed = ResumeLocked(*entry, absl::StrCat("resumed on start (", why, ")"));
      if (!resumed.ok()) LogError(id, resumed);
    } else {
      EvictLocked(*entry);
    }
  }
  if (!options_.inspect_only) AdmitWaiting();
  return absl::OkStatus();
}

absl::Status JobManager::InspectOnlyRefusal(const std::string& what) const {
  return absl::FailedPreconditionError(absl::StrCat(
      "this server only shows the jobs of ", options_.db_path_for_messages, " (--inspect); it does not ", what));
}

absl::Status JobManager::NoSuchJob(const std::string& job_id) {
  return absl::NotFoundError(absl::StrCat("no job with id '", job_id, "'"));
}

absl::StatusOr<std::string> JobManager::Submit(const std::string& study_bytes, const std::string& source_name,
                                               const std::string& owner, const std::string& actor) {
  if (options_.inspect_only) return InspectOnlyRefusal("take new jobs");
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shutdown_) return absl::UnavailableError("the server is shutting down");
  }
  MBOPT_ASSIGN_OR_RETURN(spec::Study decoded, decoder_(study_bytes, source_name));
  auto study = std::make_shared<const spec::Study>(std::move(decoded));
  // A driver is the workers' to declare, and one no worker declares is a
  // mistake to say at once; FMU support comes with a worker's build, so an
  // FMU study waits for such a worker (its status says so) instead.
  if (const scheduler::TaskNeeds needs = NeedsOf(*study); !needs.driver.empty() && !scheduler_->SomeWorkerCan(needs)) {
    const std::vector<std::string> offered = scheduler_->OfferedDrivers();
    return absl::FailedPreconditionError(absl::StrCat(
        source_name, ": scene.external.driver: no registered worker declares ", needs.Describe(),
        "; the registered workers declare ",
        offered.empty() ? "no drivers" : absl::StrCat("\"", absl::StrJoin(offered, "\", \""), "\""),
        " (a worker offers drivers with mbopt-worker serve --drivers FILE)"));
  }
  MBOPT_ASSIGN_OR_RETURN(std::unique_ptr<jobs::Job> job, jobs::Job::Create(study, options_.make_lp_solver));
  // Decoding a large study takes a while: the admission decision waits for
  // it outside the lock that admissions after every result batch take too.
  std::lock_guard<std::mutex> admit_lock(admit_mutex_);
  bool room = false;
  {
    std::lock_guard<std::mutex> admission_lock(admission_mutex_);
    room = admission_.HasRoomFor(owner);
    if (!room) MBOPT_RETURN_IF_ERROR(admission_.CheckQueueRoom(owner));
  }
  // A queued job keeps its study, not its optimizer: ResumeLocked makes one
  // when its turn comes.
  if (!room) job.reset();
  const JobState state = room ? JobState::kRunning : JobState::kQueued;
  store::JobRow row;
  // On a server with tokens (owners) an id says nothing of how many jobs
  // exist; alone on a server without tokens, job-<n> is the friendlier name.
  if (!owner.empty()) row.id = RandomJobId();
  row.study_name = study->name;
  row.source_name = source_name;
  row.owner = owner;
  row.study = study_bytes;
  row.state = jobs::JobStateName(state);
  MBOPT_ASSIGN_OR_RETURN(store::JobRow stored, store_->CreateJob(row, store::NewEvent{"submitted", source_name + ByActor(actor)}));
  auto entry = std::make_shared<Entry>();
  std::lock_guard<std::mutex> entry_lock(entry->mutex);
  entry->row = std::move(stored);
  if (room) {
    entry->layout = job->shared_layout();
  } else {
    MBOPT_ASSIGN_OR_RETURN(spec::StudyLayout layout, spec::MakeStudyLayout(*study));
    entry->layout = std::make_shared<const spec::StudyLayout>(std::move(layout));
  }
  entry->study = std::move(study);
  entry->study_ok = true;
  entry->job = std::move(job);
  const std::string id = entry->row.id;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    jobs_[id] = entry;
  }
  if (!room) {
    // CreateJob stored the state and its event.
    entry->state = JobState::kQueued;
    std::lock_guard<std::mutex> admission_lock(admission_mutex_);
    admission_.Enqueue(entry->row.seq, id, owner);
    Changed(*entry);
    return id;
  }
  (void)EnterStateLocked(*entry, JobState::kRunning, "", "", "", Persist::kAlreadyStored);
  ScheduleLocked(*entry);
  return id;
}

void JobManager::AdmitWaiting() {
  {
    // The common case, nothing waiting, costs one short lock: this runs
    // after every batch of results.
    std::lock_guard<std::mutex> admission_lock(admission_mutex_);
    if (admission_.queued() == 0) return;
  }
  std::lock_guard<std::mutex> admit_lock(admit_mutex_);
  while (true) {
    std::optional<std::string> next;
    {
      std::lock_guard<std::mutex> admission_lock(admission_mutex_);
      if (admission_.queued() == 0) return;
      next = admission_.NextToStart();
    }
    if (!next.has_value()) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (shutdown_) return;
    }
    absl::StatusOr<std::shared_ptr<Entry>> entry = Find(*next);
    if (!entry.ok()) {
      std::lock_guard<std::mutex> admission_lock(admission_mutex_);
      admission_.Remove(*next);
      continue;
    }
    std::lock_guard<std::mutex> lock((*entry)->mutex);
    if ((*entry)->state != JobState::kQueued) {
      std::lock_guard<std::mutex> admission_lock(admission_mutex_);
      admission_.Remove(*next);
      continue;
    }
    // A failure has failed the job (or left it interrupted): it left the queue either way.
    absl::Status started = ResumeLocked(**entry, "its turn in the queue came", "started");
    if (!started.ok()) LogError(*next, started);
  }
}

absl::Status JobManager::ResumeLocked(Entry& entry, const std::string& why, const std::string& event) {
  const std::string& id = entry.row.id;
  if (!entry.study_ok) {
    const std::string message = absl::StrCat("cannot resume: the stored study is invalid: ", entry.message);
    FailJobLocked(entry, message);
    return absl::FailedPreconditionError(message);
  }
  absl::StatusOr<std::unique_ptr<jobs::Job>> job = jobs::Job::Create(entry.study, options_.make_lp_solver);
  if (!job.ok()) {
    FailJobLocked(entry, absl::StrCat("cannot resume: ", job.status().message()));
    return job.status();
  }
  // Answers held for spot checks belong to the run that asked for them.
  entry.opinions.clear();
  absl::StatusOr<std::vector<jobs::AnalysisRecord>> analyses = store_->LoadAnalyses(id);
  absl::StatusOr<std::vector<store::CycleRow>> cycles =
      analyses.ok() ? store_->LoadCycles(id) : absl::StatusOr<std::vector<store::CycleRow>>(analyses.status());
  if (!cycles.ok()) {
    // The database is not readable now; the job stays resumable.
    (void)EnterStateLocked(entry, JobState::kInterrupted, absl::StrCat("cannot resume: ", cycles.status().message()),
                           "", "", Persist::kAlreadyStored);
    return cycles.status();
  }
  std::vector<std::string> logged_records;
  std::vector<slp::CycleRecord> decoded;
  for (const store::CycleRow& c : *cycles) {
    logged_records.push_back(c.record);
    absl::StatusOr<slp::CycleRecord> r = jobs::DecodeCycleRecord(c.record);
    if (!r.ok()) {
      FailJobLocked(entry, absl::StrCat("cannot resume: ", r.status().message()));
      return r.status();
    }
    decoded.push_back(*std::move(r));
  }
  absl::StatusOr<std::vector<slp::CycleRecord>> unlogged = (*job)->Replay(*analyses, logged_records);
  if (!unlogged.ok()) {
    FailJobLocked(entry, absl::StrCat("cannot resume: ", unlogged.status().message()));
    return unlogged.status();
  }
  entry.layout = (*job)->shared_layout();
  entry.job = *std::move(job);
  entry.records = std::move(decoded);
  absl::Status status = EnterStateLocked(
      entry, JobState::kRunning, "", event,
      absl::StrCat(why, "; replayed ", analyses->size(), " analyses and ", logged_records.size(), " cycle records"));
  if (!status.ok()) {
    FailJobLocked(entry, absl::StrCat("cannot resume: ", status.message()));
    return status;
  }
  if (!unlogged->empty() || !entry.job->running()) {
    MBOPT_RETURN_IF_ERROR(CommitRecordsLocked(entry, *std::move(unlogged)));
  }
  ScheduleLocked(entry);
  return absl::OkStatus();
}

void JobManager::ScheduleLocked(Entry& entry) {
  if (entry.job == nullptr || entry.state != JobState::kRunning) return;
  scheduler_->SetJobNeeds(entry.row.id, NeedsOf(*entry.study));
  std::vector<scheduler::Scheduler::NewTask> tasks;
  for (const slp::AnalysisRequest& request : entry.job->PendingRequests()) {
    tasks.push_back({request.id, std::vector<double>(request.x.data(), request.x.data() + request.x.size()),
                     request.want_gradients});
  }
  scheduler_->EnqueueAll(entry.row.id, std::move(tasks));
}

void JobManager::FailJobLocked(Entry& entry, const std::string& message) {
  LogError(entry.row.id, absl::InternalError(message));
  (void)EnterStateLocked(entry, JobState::kFailed, message, "failed", message);
}

// Commits the records the optimizer emitted, with the job's progress, in one
// transaction; when the optimizer has ended, that transaction also stores
// the final state, and the job then enters it.
absl::Status JobManager::CommitRecordsLocked(Entry& entry, std::vector<slp::CycleRecord> records) {
  Delivery delivery = RecordsDeliveryLocked(entry, std::move(records), {});
  const absl::Status committed = store_->Commit(delivery.write);
  return FinishDeliveryLocked(entry, std::move(delivery), committed);
}

JobManager::Delivery JobManager::RecordsDeliveryLocked(Entry& entry, std::vector<slp::CycleRecord> records,
                                                       std::vector<const jobs::AnalysisRecord*> analyses) {
  const jobs::Job& job = *entry.job;
  Delivery delivery;
  delivery.needs_commit = true;
  delivery.state = job.state();
  if (delivery.state == JobState::kFailed) {
    const spec::AnalysisFailure& last = entry.job->last_failure();
    delivery.message = absl::StrCat("the initial design could not be analysed (", spec::FailureKindName(last.kind),
                                    "): ", last.reason);
  } else if (delivery.state == JobState::kStalled) {
    delivery.message = job.end_reason();
    if (!records.empty() && !records.back().rejection_reason.empty()) {
      absl::StrAppend(&delivery.message, "; last rejection: ", records.back().rejection_reason);
    }
  }
  // What the user should know about the result (no feasible design, flat
  // directions) goes with the state that ends the job.
  for (const std::string& note : job.result_notes()) {
    absl::StrAppend(&delivery.message, delivery.message.empty() ? "" : "; ", note);
  }
  store::JobProgress progress;
  progress.state = jobs::JobStateName(delivery.state);
  progress.message = delivery.message;
  progress.cycles = job.cycles_completed();
  progress.analyses = job.analyses_used();
  progress.wall_seconds = WallSecondsLocked(entry);
  delivery.write.job_id = entry.row.id;
  delivery.write.analyses = std::move(analyses);
  delivery.write.cycles.reserve(records.size());
  for (const slp::CycleRecord& r : records) {
    delivery.write.cycles.push_back(store::CycleRow{0, r.cycle, r.attempt, jobs::EncodeCycleRecord(r)});
  }
  delivery.write.progress = progress;
  if (delivery.state != JobState::kRunning) {
    delivery.write.event = store::NewEvent{
        "ended", absl::StrCat(jobs::JobStateName(delivery.state), " after ", progress.cycles, " cycles")};
  }
  // While the job runs, its records are synced off the calling thread (the
  // worker's answer, and its next tasks, do not wait for the sync); the
  // records that end it are synced by their commit.
  delivery.write.defer_sync =
      store_->durability() == store::Durability::kCycles && delivery.state == JobState::kRunning;
  delivery.records = std::move(records);
  return delivery;
}

absl::Status JobManager::FinishDeliveryLocked(Entry& entry, Delivery delivery, const absl::Status& committed) {
  const bool with_records = delivery.write.progress.has_value();
  if (!committed.ok()) {
    std::vector<std::string> what;
    if (!delivery.write.analyses.empty()) what.push_back("analyses");
    if (with_records) what.push_back("cycle records");
    FailJobLocked(entry, absl::StrCat("cannot log ", absl::StrJoin(what, " and "), ": ", committed.message()));
    return committed;
  }
  if (with_records) {
    const std::int64_t rows = static_cast<std::int64_t>(delivery.records.size());
    if (delivery.write.defer_sync) {
      MBOPT_CHECK(syncer_ != nullptr, "records committed without a sync need the syncing thread");
      const std::int64_t commit = syncer_->CommittedWithoutSync(entry.row.id);
      entry.unsynced.emplace_back(commit, std::move(delivery.records));
    } else {
      // This commit synced the log: the records still waiting are durable.
      PublishUnsyncedLocked(entry);
      for (slp::CycleRecord& r : delivery.records) entry.records.push_back(std::move(r));
    }
    std::int64_t committed_records = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      records_committed_ += rows;
      committed_records = records_committed_;
    }
    if (options_.after_record_commit) {
      for (std::int64_t n = committed_records - rows + 1; n <= committed_records; ++n) options_.after_record_commit(n);
    }
    if (delivery.state != JobState::kRunning) {
      // The write stored the state and its event.
      (void)EnterStateLocked(entry, delivery.state, delivery.message, "", "", Persist::kAlreadyStored);
      return absl::OkStatus();
    }
    entry.message = delivery.message;
  }
  Changed(entry);
  return absl::OkStatus();
}

absl::Status JobManager::DeliverLocked(Entry& entry, const std::vector<jobs::AnalysisRecord>& batch) {
  absl::StatusOr<Delivery> delivery = PrepareDeliveryLocked(entry, batch);
  if (!delivery.ok()) return delivery.status();
  if (!delivery->needs_commit) return absl::OkStatus();
  const absl::Status committed = store_->Commit(delivery->write);
  return FinishDeliveryLocked(entry, *std::move(delivery), committed);
}

absl::StatusOr<JobManager::Delivery> JobManager::PrepareDeliveryLocked(Entry& entry,
                                                                       const std::vector<jobs::AnalysisRecord>& batch) {
  if (entry.job == nullptr || entry.state != JobState::kRunning) return Delivery{};
  // The whole batch goes to the optimizer first and is then committed in one
  // transaction with the records it completed: nothing is published, and no
  // worker is told its result was taken, before that commit; a failed commit
  // fails the job. Results the optimizer no longer waits for (the job ended,
  // or an earlier result of the batch completed what it needed) are neither
  // applied nor logged, so replay meets exactly the logged ones.
  std::vector<const jobs::AnalysisRecord*> applied;
  std::vector<slp::CycleRecord> emitted;
  for (const jobs::AnalysisRecord& record : batch) {
    if (!entry.job->running()) break;
    if (!entry.job->IsPending(record.request_id)) continue;
    absl::StatusOr<std::vector<slp::CycleRecord>> records = entry.job->Apply(record);
    if (!records.ok()) {
      FailJobLocked(entry, absl::StrCat("the optimizer refused analysis ", record.request_id, ": ",
                                        records.status().message()));
      return records.status();
    }
    applied.push_back(&record);
    for (slp::CycleRecord& r : *records) emitted.push_back(std::move(r));
  }
  if (applied.empty()) return Delivery{};
  // The next tasks go out before the commit, so that workers analyse while
  // it syncs: a task is not a record anyone has seen, its result cannot be
  // taken before this commit (it needs the job's lock held here), a failed
  // commit drops the job's tasks with the job, and after a crash the resume
  // asks for them again.
  ScheduleLocked(entry);
  if (!emitted.empty() || !entry.job->running()) {
    return RecordsDeliveryLocked(entry, std::move(emitted), std::move(applied));
  }
  Delivery delivery;
  delivery.needs_commit = true;
  delivery.write = store::JobWrite{entry.row.id, std::move(applied), {}, std::nullopt};
  return delivery;
}

void JobManager::DeliverGivenUpLocked(Entry& entry, const scheduler::FinishedTask& task) {
  if (entry.job == nullptr || entry.state != JobState::kRunning) return;
  if (TakeHeldAnswerLocked(entry, task)) return;
  jobs::AnalysisRecord candidate;
  candidate.request_id = task.request_id;
  candidate.failure = spec::AnalysisFailure::Of(spec::FailureKind::kService, task.failure_reason);
  candidate.attempts = task.attempts;
  absl::StatusOr<jobs::AnalysisRecord> record = entry.job->Intake(std::move(candidate));
  if (!record.ok()) {
    LogError(entry.row.id, record.status());
    return;
  }
  absl::Status delivered = DeliverLocked(entry, {*std::move(record)});
  if (!delivered.ok()) LogError(entry.row.id, delivered);
}

absl::StatusOr<bool> JobManager::ReportResult(WorkerReport report) {
  std::vector<WorkerReport> one;
  one.push_back(std::move(report));
  return std::move(ReportResults(std::move(one)).front());
}

std::vector<absl::StatusOr<bool>> JobManager::ReportResults(std::vector<WorkerReport> reports) {
  std::vector<Contradicted> contradicted;
  std::vector<absl::StatusOr<bool>> answers = IntakeResults(std::move(reports), &contradicted);
  if (!contradicted.empty()) QuarantineContradicted(contradicted);
  AdmitWaiting();
  return answers;
}

std::vector<absl::StatusOr<bool>> JobManager::IntakeResults(std::vector<WorkerReport> reports,
                                                            std::vector<Contradicted>* contradicted) {
  std::vector<absl::StatusOr<bool>> answers(reports.size(), false);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shutdown_) {
      answers.assign(reports.size(), absl::UnavailableError("the server is shutting down"));
      return answers;
    }
  }
  // Each job's results in the order they came, under its lock. The jobs'
  // locks are taken in job id order (the map's), the same in every call, and
  // held until their results are committed: all of them in one transaction.
  struct JobBatch {
    std::shared_ptr<Entry> entry;
    std::unique_lock<std::mutex> lock;
    std::vector<jobs::AnalysisRecord> records;
    std::vector<size_t> indices;  // of the reports delivered
    absl::StatusOr<Delivery> delivery;
  };
  std::map<std::string, std::vector<size_t>> by_job;
  for (size_t i = 0; i < reports.size(); ++i) by_job[reports[i].job_id].push_back(i);
  std::vector<JobBatch> batches;
  batches.reserve(by_job.size());
  for (const auto& [job_id, indices] : by_job) {
    absl::StatusOr<std::shared_ptr<Entry>> entry = Find(job_id);
    if (!entry.ok()) {
      for (size_t i : indices) answers[i] = entry.status();
      continue;
    }
    JobBatch& batch = batches.emplace_back(JobBatch{*entry, std::unique_lock<std::mutex>((*entry)->mutex), {}, {},
                                                    Delivery{}});
    for (size_t i : indices) {
      bool held = false;
      absl::StatusOr<std::optional<jobs::AnalysisRecord>> record =
          TakeResultLocked(*batch.entry, std::move(reports[i]), &held, contradicted);
      if (!record.ok()) {
        answers[i] = record.status();
      } else if (held) {
        answers[i] = true;  // taken, for a spot check: the worker's part is done
      } else if (record->has_value()) {
        batch.records.push_back(**std::move(record));
        batch.indices.push_back(i);
      }
    }
    batch.delivery = PrepareDeliveryLocked(*batch.entry, batch.records);
  }
  std::vector<const store::JobWrite*> writes;
  for (const JobBatch& batch : batches) {
    if (batch.delivery.ok() && batch.delivery->needs_commit) writes.push_back(&batch.delivery->write);
  }
  const std::vector<absl::Status> committed = store_->CommitAll(writes);
  size_t next_write = 0;
  for (JobBatch& batch : batches) {
    absl::Status delivered = batch.delivery.status();
    if (batch.delivery.ok() && batch.delivery->needs_commit) {
      delivered = FinishDeliveryLocked(*batch.entry, *std::move(batch.delivery), committed[next_write++]);
    }
    for (size_t i : batch.indices) answers[i] = delivered.ok() ? absl::StatusOr<bool>(true) : delivered;
  }
  return answers;
}

absl::StatusOr<std::optional<jobs::AnalysisRecord>> JobManager::TakeResultLocked(
    Entry& entry, WorkerReport report, bool* held, std::vector<Contradicted>* contradicted) {
  const std::int64_t request_id = report.record.request_id;
  const std::string expected_prefix = absl::StrCat(report.job_id, "/", request_id, "/");
  if (report.task_id.rfind(expected_prefix, 0) != 0) {
    return absl::InvalidArgumentError(absl::StrCat("task id '", report.task_id, "' does not belong to job '",
                                                   report.job_id, "' request ", request_id));
  }
  if (entry.job == nullptr || entry.state != JobState::kRunning) return std::nullopt;
  if (!entry.job->IsPending(request_id)) return std::nullopt;  // answered already (another attempt won)
  // Only the public part: the job log must not hold what proves a
  // worker's registration.
  report.record.worker = scheduler::PublicWorkerId(report.worker_id);
  report.record.holder = report.holder;
  absl::StatusOr<jobs::AnalysisRecord> record = entry.job->Intake(std::move(report.record));
  if (!record.ok()) {
    // A result that does not fit its task counts as a failed attempt; the
    // worker is told why, and the task goes to another worker.
    const std::string reason = absl::StrCat("result of task ", report.task_id, ": ", record.status().message());
    absl::StatusOr<std::optional<scheduler::FinishedTask>> failed =
        scheduler_->Fail(report.worker_id, report.task_id, reason);
    if (failed.ok() && failed->has_value()) DeliverGivenUpLocked(entry, **failed);
    return absl::InvalidArgumentError(reason);
  }
  if (SpotChecked(entry.row.id, request_id, options_.verify_fraction)) {
    absl::StatusOr<bool> held_now = SpotCheckLocked(entry, report, &*record, contradicted);
    if (absl::IsPermissionDenied(held_now.status())) return held_now.status();
    if (!held_now.ok()) return std::nullopt;
    if (*held_now) {
      *held = true;
      return std::nullopt;
    }
  }
  absl::StatusOr<scheduler::FinishedTask> finished = scheduler_->Complete(report.worker_id, report.task_id);
  // Another worker's task: refused, and the caller is told (and logs it).
  if (absl::IsPermissionDenied(finished.status())) return finished.status();
  if (!finished.ok()) return std::nullopt;
  record->attempts = finished->attempts;
  record->latency_seconds = finished->latency_seconds;
  return std::optional<jobs::AnalysisRecord>(*std::move(record));
}

void JobManager::GiveUp(const scheduler::FinishedTask& task) {
  absl::StatusOr<std::shared_ptr<Entry>> entry = Find(task.job_id);
  if (!entry.ok()) return;
  std::lock_guard<std::mutex> lock((*entry)->mutex);
  DeliverGivenUpLocked(**entry, task);
}

absl::Status JobManager::ReportWorkerError(const std::string& worker_id, const std::string& task_id,
                                           const std::string& reason) {
  MBOPT_ASSIGN_OR_RETURN(std::optional<scheduler::FinishedTask> given_up,
                         scheduler_->Fail(worker_id, task_id, reason));
  if (given_up) GiveUp(*given_up);
  AdmitWaiting();
  return absl::OkStatus();
}

void JobManager::WorkerLost(const std::string& worker_id) {
  for (const scheduler::FinishedTask& task : scheduler_->WorkerLost(worker_id)) GiveUp(task);
  AdmitWaiting();
}

void JobManager::ExpireLeases() {
  for (const scheduler::FinishedTask& task : scheduler_->ExpireLeases()) GiveUp(task);
  AdmitWaiting();
}

absl::StatusOr<JobSummaryData> JobManager::Cancel(const std::string& job_id, const std::string& actor) {
  if (options_.inspect_only) return InspectOnlyRefusal("cancel jobs");
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<Entry> entry, Find(job_id));
  JobSummaryData summary;
  {
    std::lock_guard<std::mutex> lock(entry->mutex);
    if (!Running(entry->state) && entry->state != JobState::kInterrupted) {
      return absl::FailedPreconditionError(absl::StrCat("job '", job_id, "' has already ended (",
                                                        jobs::JobStateName(entry->state), ")"));
    }
    MBOPT_RETURN_IF_ERROR(EnterStateLocked(*entry, JobState::kCancelled,
                                           "cancelled on request; `resume` continues it", "cancelled",
                                           actor.empty() ? "" : absl::StrCat("by ", actor)));
    summary = SummaryLocked(*entry);
  }
  AdmitWaiting();
  return summary;
}

absl::StatusOr<JobSummaryData> JobManager::Resume(const std::string& job_id, const std::string& actor) {
  if (options_.inspect_only) return InspectOnlyRefusal("resume jobs");
  std::lock_guard<std::mutex> admit_lock(admit_mutex_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shutdown_) return absl::UnavailableError("the server is shutting down");
  }
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<Entry> entry, Find(job_id));
  std::lock_guard<std::mutex> lock(entry->mutex);
  if (entry->state == JobState::kRunning || entry->state == JobState::kQueued) return SummaryLocked(*entry);
  if (!jobs::IsResumable(entry->state)) {
    return absl::FailedPreconditionError(absl::StrCat("job '", job_id, "' has ended (",
                                                      jobs::JobStateName(entry->state), ") and cannot be resumed"));
  }
  MBOPT_RETURN_IF_ERROR(RestoreLocked(*entry));
  bool room = false;
  {
    std::lock_guard<std::mutex> admission_lock(admission_mutex_);
    room = admission_.HasRoomFor(entry->row.owner);
    if (!room) MBOPT_RETURN_IF_ERROR(admission_.CheckQueueRoom(entry->row.owner));
  }
  if (!room) {
    MBOPT_RETURN_IF_ERROR(EnterStateLocked(*entry, JobState::kQueued, "", "queued",
                                           "resume asked while the running limits are reached" + ByActor(actor)));
    {
      std::lock_guard<std::mutex> admission_lock(admission_mutex_);
      admission_.Enqueue(entry->row.seq, job_id, entry->row.owner);
    }
    return SummaryLocked(*entry);
  }
  MBOPT_RETURN_IF_ERROR(ResumeLocked(*entry, "resumed on request" + ByActor(actor)));
  return SummaryLocked(*entry);
}

void JobManager::Shutdown() {
  std::vector<std::shared_ptr<Entry>> entries;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shutdown_) return;
    shutdown_ = true;
    for (const auto& [id, entry] : jobs_) entries.push_back(entry);
  }
  scheduler_->Shutdown();
  for (const auto& entry : entries) {
    std::lock_guard<std::mutex> lock(entry->mutex);
    // A queued job stays queued: it waits for its turn after the restart too.
    if (!Running(entry->state) || entry->state == JobState::kQueued) continue;
    (void)EnterStateLocked(*entry, JobState::kInterrupted, "the server was stopped; the job resumes when it starts again",
                           "interrupted", "server stopped");
  }
}

}  // namespace mbopt::jobs::manager
