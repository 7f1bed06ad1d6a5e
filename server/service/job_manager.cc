#include "server/service/job_manager.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/status_macros.h"
#include "server/jobs/analysis_gradients.h"
#include "server/jobs/record_codec.h"

namespace mbopt::service {

using jobs::JobState;
using Clock = std::chrono::steady_clock;

struct JobManager::Entry {
  std::mutex mutex;
  std::condition_variable changed;

  store::JobRow row;  // id, names, study bytes, created; progress as loaded
  JobState state = JobState::kQueued;
  std::string message;

  bool study_ok = false;
  spec::Study study;
  spec::StudyLayout layout;
  std::unique_ptr<jobs::Job> job;  // the optimizer of the current run

  std::vector<slp::CycleRecord> records;
  std::int64_t version = 0;
  std::string last_failure;  // of the latest failed analysis

  double wall_before_s = 0;  // running time of earlier runs
  bool timing = false;
  Clock::time_point run_started;
};

namespace {

std::vector<double> ToVector(const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

Eigen::VectorXd ToEigen(const std::vector<double>& v) {
  Eigen::VectorXd e(static_cast<Eigen::Index>(v.size()));
  for (size_t i = 0; i < v.size(); ++i) e[static_cast<Eigen::Index>(i)] = v[i];
  return e;
}

// The optimizer's view of a logged analysis: live delivery and replay give
// it exactly this, so a resumed job sees what the first run saw.
slp::AnalysisResult ResultOf(const store::AnalysisRow& row, const slp::ProblemSpec& problem) {
  slp::AnalysisResult result;
  result.request_id = row.request_id;
  result.outcome = row.ok ? slp::AnalysisOutcome::kOk : slp::AnalysisOutcome::kFailed;
  result.failure_reason = row.failure_reason;
  if (row.ok) {
    result.objective_terms = ToEigen(row.objective_terms);
    result.constraint_values = ToEigen(row.constraint_values);
    jobs::AttachGradients(problem, row.objective_gradients, row.constraint_gradients, &result);
  }
  return result;
}

void LogError(const std::string& job_id, const absl::Status& status) {
  std::cerr << "mbopt-server: job " << job_id << ": " << status << std::endl;
}

}  // namespace

JobManager::JobManager(store::Store* store, scheduler::Scheduler* scheduler, StudyDecoder decoder,
                       JobManagerOptions options)
    : store_(store), scheduler_(scheduler), decoder_(std::move(decoder)), options_(std::move(options)) {}

JobManager::~JobManager() = default;

absl::StatusOr<std::shared_ptr<JobManager::Entry>> JobManager::Find(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = jobs_.find(job_id);
  if (it == jobs_.end()) return absl::NotFoundError(absl::StrCat("no job with id '", job_id, "'"));
  return it->second;
}

void JobManager::Changed(Entry& entry) {
  entry.version += 1;
  entry.changed.notify_all();
}

double JobManager::WallSecondsLocked(const Entry& entry) const {
  double wall = entry.wall_before_s;
  if (entry.timing) wall += std::chrono::duration<double>(Clock::now() - entry.run_started).count();
  return wall;
}

static void StopTiming(double& wall_before_s, bool& timing, Clock::time_point started) {
  if (!timing) return;
  wall_before_s += std::chrono::duration<double>(Clock::now() - started).count();
  timing = false;
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
    absl::StatusOr<spec::Study> study = decoder_(entry->row.study, entry->row.source_name);
    if (study.ok()) {
      absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(*study);
      if (layout.ok()) {
        entry->study = *std::move(study);
        entry->layout = *std::move(layout);
        entry->study_ok = true;
      } else {
        entry->message = std::string(layout.status().message());
      }
    } else {
      entry->message = std::string(study.status().message());
    }
    absl::StatusOr<std::vector<store::CycleRow>> cycles = store_->LoadCycles(id);
    if (cycles.ok()) {
      for (const store::CycleRow& c : *cycles) {
        absl::StatusOr<slp::CycleRecord> record = jobs::DecodeCycleRecord(c.record);
        if (!record.ok()) {
          cycles = record.status();
          break;
        }
        entry->records.push_back(*std::move(record));
      }
    }
    {
      std::lock_guard<std::mutex> jobs_lock(mutex_);
      jobs_[id] = entry;
    }
    if (!cycles.ok()) {
      FailJobLocked(*entry, absl::StrCat("cannot read the cycle log: ", cycles.status().message()));
      continue;
    }
    if (entry->state == JobState::kRunning || entry->state == JobState::kQueued ||
        entry->state == JobState::kInterrupted) {
      const std::string why = entry->state == JobState::kInterrupted ? "the server was stopped"
                                                                     : "the server ended without stopping the job";
      absl::Status resumed = ResumeLocked(*entry, absl::StrCat("resumed on start (", why, ")"));
      if (!resumed.ok()) LogError(id, resumed);
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<std::string> JobManager::Submit(const std::string& study_bytes, const std::string& source_name) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shutdown_) return absl::UnavailableError("the server is shutting down");
  }
  MBOPT_ASSIGN_OR_RETURN(spec::Study study, decoder_(study_bytes, source_name));
  MBOPT_ASSIGN_OR_RETURN(std::unique_ptr<jobs::Job> job, jobs::Job::Create(study));
  MBOPT_ASSIGN_OR_RETURN(spec::StudyLayout layout, spec::MakeStudyLayout(study));
  store::JobRow row;
  row.study_name = study.name;
  row.source_name = source_name;
  row.study = study_bytes;
  row.state = jobs::JobStateName(JobState::kRunning);
  MBOPT_ASSIGN_OR_RETURN(store::JobRow stored, store_->CreateJob(row));
  auto entry = std::make_shared<Entry>();
  std::lock_guard<std::mutex> entry_lock(entry->mutex);
  entry->row = std::move(stored);
  entry->state = JobState::kRunning;
  entry->study = std::move(study);
  entry->layout = std::move(layout);
  entry->study_ok = true;
  entry->job = std::move(job);
  entry->timing = true;
  entry->run_started = Clock::now();
  const std::string id = entry->row.id;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    jobs_[id] = entry;
  }
  (void)store_->AddEvent(id, "submitted", source_name);
  FinishIfDoneLocked(*entry);
  if (entry->state == JobState::kRunning) ScheduleLocked(*entry);
  Changed(*entry);
  return id;
}

absl::Status JobManager::ResumeLocked(Entry& entry, const std::string& why) {
  const std::string& id = entry.row.id;
  if (!entry.study_ok) {
    const std::string message = absl::StrCat("cannot resume: the stored study is invalid: ", entry.message);
    FailJobLocked(entry, message);
    return absl::FailedPreconditionError(message);
  }
  absl::StatusOr<std::unique_ptr<jobs::Job>> job = jobs::Job::Create(entry.study);
  if (!job.ok()) {
    FailJobLocked(entry, absl::StrCat("cannot resume: ", job.status().message()));
    return job.status();
  }
  absl::StatusOr<std::vector<store::AnalysisRow>> analyses = store_->LoadAnalyses(id);
  absl::StatusOr<std::vector<store::CycleRow>> cycles =
      analyses.ok() ? store_->LoadCycles(id) : absl::StatusOr<std::vector<store::CycleRow>>(analyses.status());
  if (!cycles.ok()) {
    // The database is not readable now; the job stays resumable.
    entry.state = JobState::kInterrupted;
    entry.message = absl::StrCat("cannot resume: ", cycles.status().message());
    Changed(entry);
    return cycles.status();
  }
  std::vector<jobs::LoggedAnalysis> logged;
  logged.reserve(analyses->size());
  for (const store::AnalysisRow& a : *analyses) {
    jobs::LoggedAnalysis l;
    l.result = ResultOf(a, (*job)->problem());
    l.x_scaled = a.x_scaled;
    logged.push_back(std::move(l));
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
  absl::StatusOr<std::vector<slp::CycleRecord>> unlogged = (*job)->Replay(logged, logged_records);
  if (!unlogged.ok()) {
    FailJobLocked(entry, absl::StrCat("cannot resume: ", unlogged.status().message()));
    return unlogged.status();
  }
  entry.job = *std::move(job);
  entry.records = std::move(decoded);
  entry.state = JobState::kRunning;
  entry.message.clear();
  entry.timing = true;
  entry.run_started = Clock::now();
  absl::Status status = store_->SetJobState(id, jobs::JobStateName(JobState::kRunning), "");
  if (!status.ok()) {
    FailJobLocked(entry, absl::StrCat("cannot resume: ", status.message()));
    return status;
  }
  (void)store_->AddEvent(id, "resumed",
                         absl::StrCat(why, "; replayed ", logged.size(), " analyses and ", logged_records.size(),
                                      " cycle records"));
  if (!unlogged->empty() || entry.job->optimizer().state() != slp::RunState::kRunning) {
    MBOPT_RETURN_IF_ERROR(CommitRecordsLocked(entry, *std::move(unlogged)));
  }
  FinishIfDoneLocked(entry);
  if (entry.state == JobState::kRunning) ScheduleLocked(entry);
  Changed(entry);
  return absl::OkStatus();
}

void JobManager::ScheduleLocked(Entry& entry) {
  if (entry.job == nullptr || entry.state != JobState::kRunning) return;
  for (const slp::AnalysisRequest& request : entry.job->PendingRequests()) {
    scheduler_->Enqueue(entry.row.id, request.id, ToVector(request.x), request.want_gradients);
  }
}

void JobManager::FailJobLocked(Entry& entry, const std::string& message) {
  LogError(entry.row.id, absl::InternalError(message));
  entry.state = JobState::kFailed;
  entry.message = message;
  StopTiming(entry.wall_before_s, entry.timing, entry.run_started);
  scheduler_->DropJob(entry.row.id);
  absl::Status status = store_->SetJobState(entry.row.id, jobs::JobStateName(JobState::kFailed), message);
  if (!status.ok()) LogError(entry.row.id, status);
  (void)store_->AddEvent(entry.row.id, "failed", message);
  Changed(entry);
}

absl::Status JobManager::CommitRecordsLocked(Entry& entry, std::vector<slp::CycleRecord> records) {
  const slp::SlpOptimizer& optimizer = entry.job->optimizer();
  JobState state = jobs::JobStateOf(optimizer.state());
  std::string message;
  if (state == JobState::kFailed) {
    message = absl::StrCat("the initial design could not be analysed: ", entry.last_failure);
  } else if (state == JobState::kStalled) {
    message = "the move limits collapsed or every trial point failed";
    if (!records.empty() && !records.back().rejection_reason.empty()) {
      absl::StrAppend(&message, "; last rejection: ", records.back().rejection_reason);
    }
  }
  store::JobProgress progress;
  progress.state = jobs::JobStateName(state);
  progress.message = message;
  progress.cycles = optimizer.cycles_completed();
  progress.analyses = optimizer.analyses_used();
  progress.wall_seconds = WallSecondsLocked(entry);
  std::vector<store::CycleRow> rows;
  rows.reserve(records.size());
  for (const slp::CycleRecord& r : records) {
    rows.push_back(store::CycleRow{0, r.cycle, r.attempt, jobs::EncodeCycleRecord(r)});
  }
  absl::Status status = store_->CommitCycle(entry.row.id, rows, progress);
  if (!status.ok()) {
    FailJobLocked(entry, absl::StrCat("cannot log cycle records: ", status.message()));
    return status;
  }
  entry.message = message;
  for (slp::CycleRecord& r : records) entry.records.push_back(std::move(r));
  std::int64_t committed = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    records_committed_ += static_cast<std::int64_t>(rows.size());
    committed = records_committed_;
  }
  if (options_.after_record_commit) {
    for (std::int64_t n = committed - static_cast<std::int64_t>(rows.size()) + 1; n <= committed; ++n) {
      options_.after_record_commit(n);
    }
  }
  return absl::OkStatus();
}

void JobManager::FinishIfDoneLocked(Entry& entry) {
  if (entry.job == nullptr || entry.state != JobState::kRunning) return;
  const slp::RunState run = entry.job->optimizer().state();
  if (run == slp::RunState::kRunning) return;
  entry.state = jobs::JobStateOf(run);
  StopTiming(entry.wall_before_s, entry.timing, entry.run_started);
  scheduler_->DropJob(entry.row.id);
  (void)store_->AddEvent(entry.row.id, "ended",
                         absl::StrCat(jobs::JobStateName(entry.state), " after ",
                                      entry.job->optimizer().cycles_completed(), " cycles"));
}

absl::Status JobManager::DeliverLocked(Entry& entry, const store::AnalysisRow& row) {
  if (entry.job == nullptr || entry.state != JobState::kRunning) return absl::OkStatus();
  absl::Status status = store_->AddAnalysis(row);
  if (!status.ok()) {
    FailJobLocked(entry, absl::StrCat("cannot log analysis ", row.request_id, ": ", status.message()));
    return status;
  }
  if (!row.ok) entry.last_failure = row.failure_reason;
  absl::StatusOr<std::vector<slp::CycleRecord>> records = entry.job->Submit(ResultOf(row, entry.job->problem()));
  if (!records.ok()) {
    FailJobLocked(entry, absl::StrCat("the optimizer refused analysis ", row.request_id, ": ",
                                      records.status().message()));
    return records.status();
  }
  if (!records->empty() || entry.job->optimizer().state() != slp::RunState::kRunning) {
    MBOPT_RETURN_IF_ERROR(CommitRecordsLocked(entry, *std::move(records)));
  }
  FinishIfDoneLocked(entry);
  ScheduleLocked(entry);
  Changed(entry);
  return absl::OkStatus();
}

absl::StatusOr<bool> JobManager::ReportResult(const WorkerResult& r) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shutdown_) return absl::UnavailableError("the server is shutting down");
  }
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<Entry> entry, Find(r.job_id));
  std::lock_guard<std::mutex> lock(entry->mutex);
  const std::string expected_prefix = absl::StrCat(r.job_id, "/", r.request_id, "/");
  if (r.task_id.rfind(expected_prefix, 0) != 0) {
    return absl::InvalidArgumentError(absl::StrCat("task id '", r.task_id, "' does not belong to job '", r.job_id,
                                                   "' request ", r.request_id));
  }
  if (entry->job == nullptr || entry->state != JobState::kRunning) return false;
  if (r.ok) {
    const size_t terms = static_cast<size_t>(entry->job->problem().num_objective_terms);
    const size_t rows = static_cast<size_t>(entry->job->problem().num_constraints());
    if (r.objective_terms.size() != terms || r.constraint_values.size() != rows) {
      const std::string reason =
          absl::StrCat("result of task ", r.task_id, " has ", r.objective_terms.size(), " objective terms and ",
                       r.constraint_values.size(), " constraint values; job ", r.job_id, " needs ", terms,
                       " and ", rows);
      absl::StatusOr<std::optional<scheduler::FinishedTask>> failed = scheduler_->Fail(r.worker_id, r.task_id, reason);
      if (failed.ok() && failed->has_value()) {
        store::AnalysisRow row;
        row.job_id = r.job_id;
        row.request_id = (*failed)->request_id;
        row.x_scaled = (*failed)->x_scaled;
        row.ok = false;
        row.failure_reason = (*failed)->failure_reason;
        row.attempts = (*failed)->attempts;
        (void)DeliverLocked(*entry, row);
      }
      return absl::InvalidArgumentError(reason);
    }
  }
  bool wanted_gradients = false;
  for (const slp::AnalysisRequest& request : entry->job->PendingRequests()) {
    if (request.id == r.request_id) wanted_gradients = request.want_gradients;
  }
  absl::StatusOr<scheduler::FinishedTask> finished = scheduler_->Complete(r.worker_id, r.task_id);
  if (!finished.ok()) return false;
  store::AnalysisRow row;
  row.job_id = r.job_id;
  row.request_id = finished->request_id;
  row.x_scaled = finished->x_scaled;
  row.ok = r.ok;
  row.failure_reason = r.ok ? "" : (r.failure_reason.empty() ? "the analysis failed" : r.failure_reason);
  if (r.ok) {
    row.objective_terms = r.objective_terms;
    row.constraint_values = r.constraint_values;
  }
  if (r.ok && wanted_gradients) {
    // Logged as the optimizer will get them: unusable gradients are none.
    const std::string defect = jobs::GradientDefect(entry->job->problem(), r.objective_gradients,
                                                    r.constraint_gradients);
    if (!defect.empty()) {
      row.gradients_unavailable = absl::StrCat("unusable gradients from the worker: ", defect);
    } else if (r.objective_gradients.empty()) {
      row.gradients_unavailable =
          r.gradients_unavailable.empty() ? "the worker sent no gradients" : r.gradients_unavailable;
    } else {
      row.objective_gradients = r.objective_gradients;
      row.constraint_gradients = r.constraint_gradients;
    }
  }
  row.worker = r.worker_id;
  row.wall_seconds = r.wall_seconds;
  row.attempts = finished->attempts;
  row.counters = r.counters;
  MBOPT_RETURN_IF_ERROR(DeliverLocked(*entry, row));
  return true;
}

void JobManager::GiveUp(const scheduler::FinishedTask& task) {
  absl::StatusOr<std::shared_ptr<Entry>> entry = Find(task.job_id);
  if (!entry.ok()) return;
  std::lock_guard<std::mutex> lock((*entry)->mutex);
  store::AnalysisRow row;
  row.job_id = task.job_id;
  row.request_id = task.request_id;
  row.x_scaled = task.x_scaled;
  row.ok = false;
  row.failure_reason = task.failure_reason;
  row.attempts = task.attempts;
  (void)DeliverLocked(**entry, row);
}

absl::Status JobManager::ReportWorkerError(const std::string& worker_id, const std::string& task_id,
                                           const std::string& reason) {
  MBOPT_ASSIGN_OR_RETURN(std::optional<scheduler::FinishedTask> given_up,
                         scheduler_->Fail(worker_id, task_id, reason));
  if (given_up) GiveUp(*given_up);
  return absl::OkStatus();
}

void JobManager::ExpireLeases() {
  for (const scheduler::FinishedTask& task : scheduler_->ExpireLeases()) GiveUp(task);
}

JobSummaryData JobManager::SummaryLocked(const Entry& entry) const {
  JobSummaryData s;
  s.job_id = entry.row.id;
  s.study_name = entry.row.study_name;
  s.state = entry.state;
  s.message = entry.message;
  s.created_unix_ms = entry.row.created_unix_ms;
  s.wall_seconds = WallSecondsLocked(entry);
  s.cycles = entry.row.cycles;
  s.analyses = entry.row.analyses;
  Eigen::VectorXd design;
  if (entry.study_ok) {
    s.objective_unit = entry.study.objective.unit;
    s.max_cycles = entry.study.optimizer.max_cycles;
    design.resize(static_cast<Eigen::Index>(entry.study.variables.size()));
    for (size_t i = 0; i < entry.study.variables.size(); ++i) {
      const spec::DesignVariable& v = entry.study.variables[i];
      s.design_names.push_back(v.name);
      s.design_units.push_back(v.parameter >= 0 && static_cast<size_t>(v.parameter) < entry.study.scene.parameters.size()
                                   ? entry.study.scene.parameters[static_cast<size_t>(v.parameter)].unit
                                   : "");
      design[static_cast<Eigen::Index>(i)] = v.initial;
    }
  }
  if (entry.job != nullptr) {
    const slp::SlpOptimizer& optimizer = entry.job->optimizer();
    s.cycles = optimizer.cycles_completed();
    s.analyses = optimizer.analyses_used();
    if (!entry.records.empty()) {
      design = optimizer.current_design();
      s.objective = optimizer.current_objective();
      s.max_violation = optimizer.current_max_violation();
    }
  } else if (!entry.records.empty()) {
    // Not running in this process: the best design is the last accepted
    // trial point, or the first x0 when none was accepted.
    const slp::CycleRecord* accepted = nullptr;
    for (const slp::CycleRecord& r : entry.records) {
      if (r.accepted) accepted = &r;
    }
    if (accepted != nullptr) {
      design = accepted->x_trial;
      s.objective = accepted->objective_trial;
      s.max_violation = accepted->max_violation_trial;
    } else {
      design = entry.records.front().x0;
      s.objective = entry.records.front().objective_x0;
      s.max_violation = entry.records.front().max_violation_x0;
    }
  }
  if (entry.study_ok && static_cast<size_t>(design.size()) == entry.study.variables.size()) {
    for (size_t i = 0; i < entry.study.variables.size(); ++i) {
      s.design.push_back(entry.study.variables[i].scale * design[static_cast<Eigen::Index>(i)]);
    }
  }
  return s;
}

JobView JobManager::ViewLocked(const Entry& entry, std::size_t first_record) const {
  JobView view;
  view.summary = SummaryLocked(entry);
  view.first_record = std::min(first_record, entry.records.size());
  view.records.assign(entry.records.begin() + static_cast<std::ptrdiff_t>(view.first_record), entry.records.end());
  view.version = entry.version;
  view.ended = entry.state != JobState::kRunning && entry.state != JobState::kQueued;
  if (entry.study_ok) {
    for (const spec::ConstraintRow& row : entry.layout.rows) view.row_names.push_back(row.name);
    for (const spec::DesignVariable& v : entry.study.variables) view.variable_scales.push_back(v.scale);
  }
  view.study_bytes = entry.row.study;
  return view;
}

absl::StatusOr<JobView> JobManager::Get(const std::string& job_id, std::size_t first_record) {
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<Entry> entry, Find(job_id));
  std::lock_guard<std::mutex> lock(entry->mutex);
  return ViewLocked(*entry, first_record);
}

absl::StatusOr<std::vector<JobSummaryData>> JobManager::List() {
  std::vector<std::shared_ptr<Entry>> entries;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [id, entry] : jobs_) entries.push_back(entry);
  }
  // In submission order (the store's sequence number; ids sort as text).
  std::vector<std::pair<std::int64_t, JobSummaryData>> ordered;
  for (const auto& entry : entries) {
    std::lock_guard<std::mutex> lock(entry->mutex);
    ordered.emplace_back(entry->row.seq, SummaryLocked(*entry));
  }
  std::sort(ordered.begin(), ordered.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<JobSummaryData> summaries;
  for (auto& [seq, summary] : ordered) summaries.push_back(std::move(summary));
  return summaries;
}

absl::StatusOr<JobSummaryData> JobManager::Cancel(const std::string& job_id) {
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<Entry> entry, Find(job_id));
  std::lock_guard<std::mutex> lock(entry->mutex);
  if (entry->state != JobState::kRunning && entry->state != JobState::kQueued &&
      entry->state != JobState::kInterrupted) {
    return absl::FailedPreconditionError(absl::StrCat("job '", job_id, "' has already ended (",
                                                      jobs::JobStateName(entry->state), ")"));
  }
  entry->state = JobState::kCancelled;
  entry->message = "cancelled on request; `resume` continues it";
  StopTiming(entry->wall_before_s, entry->timing, entry->run_started);
  scheduler_->DropJob(job_id);
  MBOPT_RETURN_IF_ERROR(store_->SetJobState(job_id, jobs::JobStateName(JobState::kCancelled), entry->message));
  (void)store_->AddEvent(job_id, "cancelled", "");
  Changed(*entry);
  return SummaryLocked(*entry);
}

absl::StatusOr<JobSummaryData> JobManager::Resume(const std::string& job_id) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shutdown_) return absl::UnavailableError("the server is shutting down");
  }
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<Entry> entry, Find(job_id));
  std::lock_guard<std::mutex> lock(entry->mutex);
  if (entry->state == JobState::kRunning) return SummaryLocked(*entry);
  if (!jobs::IsResumable(entry->state)) {
    return absl::FailedPreconditionError(absl::StrCat("job '", job_id, "' has ended (",
                                                      jobs::JobStateName(entry->state),
                                                      ") and cannot be resumed"));
  }
  MBOPT_RETURN_IF_ERROR(ResumeLocked(*entry, "resumed on request"));
  return SummaryLocked(*entry);
}

absl::StatusOr<JobView> JobManager::WaitForChange(const std::string& job_id, std::size_t first_record,
                                                  std::int64_t version_seen, std::int64_t max_wait_ms) {
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<Entry> entry, Find(job_id));
  std::unique_lock<std::mutex> lock(entry->mutex);
  entry->changed.wait_for(lock, std::chrono::milliseconds(std::max<std::int64_t>(0, max_wait_ms)),
                          [&] { return entry->version != version_seen; });
  return ViewLocked(*entry, first_record);
}

absl::StatusOr<std::string> JobManager::StudyBytes(const std::string& job_id) {
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<Entry> entry, Find(job_id));
  std::lock_guard<std::mutex> lock(entry->mutex);
  return entry->row.study;
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
    if (entry->state != JobState::kRunning && entry->state != JobState::kQueued) continue;
    entry->state = JobState::kInterrupted;
    entry->message = "the server was stopped; the job resumes when it starts again";
    StopTiming(entry->wall_before_s, entry->timing, entry->run_started);
    absl::Status status =
        store_->SetJobState(entry->row.id, jobs::JobStateName(JobState::kInterrupted), entry->message);
    if (!status.ok()) LogError(entry->row.id, status);
    (void)store_->AddEvent(entry->row.id, "interrupted", "server stopped");
    Changed(*entry);
  }
}

}  // namespace mbopt::service
