// The job manager's spot checks (spot_check.h): answers held until a second
// worker agrees, and the quarantine of a worker whose answer two others
// contradict.
#include <cstring>
#include <iostream>
#include <iterator>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/status_macros.h"
#include "server/jobs/manager/job_entry.h"
#include "server/jobs/manager/job_manager.h"
#include "server/jobs/manager/spot_check.h"
#include "server/jobs/record_codec.h"
#include "server/scheduler/scheduler.h"

namespace mbopt::jobs::manager {
namespace {

// "w-3 (token rack1)", or "w-3" for a worker of a server without tokens.
std::string WorkerNamed(const std::string& public_id, const std::string& holder) {
  return holder.empty() ? public_id : absl::StrCat(public_id, " (token ", holder, ")");
}

bool SameDesign(const Eigen::VectorXd& x, const std::vector<double>& logged) {
  return static_cast<std::size_t>(x.size()) == logged.size() &&
         (logged.empty() || std::memcmp(x.data(), logged.data(), logged.size() * sizeof(double)) == 0);
}

}  // namespace

absl::StatusOr<std::int64_t> JobManager::RecomputeUncheckedLocked(Entry& entry, const std::string& public_id,
                                                                  std::size_t* kept_records) {
  if (entry.job == nullptr || entry.state != jobs::JobState::kRunning) return 0;
  const std::string& id = entry.row.id;
  MBOPT_ASSIGN_OR_RETURN(std::vector<jobs::AnalysisRecord> logged, store_->LoadAnalyses(id));
  // Its checked answers were confirmed by another worker; the others are
  // only its word.
  std::map<std::int64_t, const jobs::AnalysisRecord*> trusted;
  bool any_suspect = false;
  for (const jobs::AnalysisRecord& a : logged) {
    if (a.worker == public_id && !SpotChecked(id, a.request_id, options_.verify_fraction)) {
      any_suspect = true;
    } else {
      trusted[a.request_id] = &a;
    }
  }
  if (!any_suspect) return 0;
  MBOPT_ASSIGN_OR_RETURN(std::vector<store::CycleRow> cycles, store_->LoadCycles(id));
  // A fresh optimizer fed the log without the suspect answers, as a resume
  // replays it: it stops where the first of them was needed, and the
  // records it makes on the way are the logged ones, which it keeps.
  MBOPT_ASSIGN_OR_RETURN(std::unique_ptr<jobs::Job> job, jobs::Job::Create(entry.study, options_.make_lp_solver));
  std::set<std::int64_t> used;
  std::size_t records = 0;
  while (true) {
    const jobs::AnalysisRecord* next = nullptr;
    for (const slp::AnalysisRequest& request : job->PendingRequests()) {
      auto found = trusted.find(request.id);
      if (found != trusted.end() && SameDesign(request.x, found->second->x_scaled)) {
        next = found->second;
        break;
      }
    }
    if (next == nullptr) break;
    MBOPT_ASSIGN_OR_RETURN(std::vector<slp::CycleRecord> made, job->Apply(*next));
    used.insert(next->request_id);
    for (const slp::CycleRecord& r : made) {
      if (records >= cycles.size() || jobs::EncodeCycleRecord(r) != cycles[records].record) {
        return absl::DataLossError(absl::StrCat("job ", id, ": replaying its log without the worker's answers gave "
                                                "a record the log does not hold; nothing was taken back"));
      }
      ++records;
    }
  }
  std::vector<std::int64_t> forget;
  for (const jobs::AnalysisRecord& a : logged) {
    if (used.count(a.request_id) == 0) forget.push_back(a.request_id);
  }
  std::vector<slp::CycleRecord> kept;
  for (std::size_t i = 0; i < records; ++i) {
    MBOPT_ASSIGN_OR_RETURN(slp::CycleRecord r, jobs::DecodeCycleRecord(cycles[i].record));
    kept.push_back(std::move(r));
  }
  MBOPT_RETURN_IF_ERROR(store_->RewindJob(id, forget, static_cast<std::int64_t>(records)));
  // The job's tasks and answers held for checks belong to the run taken
  // back; a result of one arriving now is dropped as not outstanding.
  scheduler_->DropJob(id);
  entry.opinions.clear();
  entry.unsynced.clear();
  entry.records = std::move(kept);
  entry.layout = job->shared_layout();
  entry.job = std::move(job);
  ScheduleLocked(entry);
  Changed(entry);
  *kept_records = records;
  return static_cast<std::int64_t>(forget.size());
}

absl::StatusOr<bool> JobManager::SpotCheckLocked(Entry& entry, const WorkerReport& report,
                                                 jobs::AnalysisRecord* record, std::vector<Contradicted>* liars) {
  const std::int64_t request_id = record->request_id;
  std::vector<SpotCheckOpinion>& opinions = entry.opinions[request_id];
  std::set<std::string> answered = {report.worker_id};
  for (const SpotCheckOpinion& opinion : opinions) answered.insert(opinion.worker_id);
  const SpotCheckOpinion* agreeing = nullptr;
  for (const SpotCheckOpinion& opinion : opinions) {
    if (SameAnswer(opinion.record, *record)) {
      agreeing = &opinion;
      break;
    }
  }
  if (agreeing != nullptr) {
    // Two workers agree: that answer is taken (as the first of them logged
    // it), and whoever said otherwise is quarantined once the locks are
    // released (QuarantineContradicted).
    std::vector<std::string> agreed_by;
    for (const SpotCheckOpinion& opinion : opinions) {
      if (SameAnswer(opinion.record, *record)) agreed_by.push_back(opinion.record.worker);
    }
    agreed_by.push_back(record->worker);
    for (const SpotCheckOpinion& opinion : opinions) {
      if (!SameAnswer(opinion.record, *record)) {
        liars->push_back(Contradicted{opinion.worker_id, opinion.record.worker, opinion.record.holder, entry.row.id,
                                      request_id, absl::StrJoin(agreed_by, " and ")});
      }
    }
    *record = agreeing->record;
    entry.opinions.erase(request_id);
    return false;
  }
  if (static_cast<int>(opinions.size()) + 1 >= kMaxSpotCheckOpinions) {
    // Nobody agrees with anybody: no answer can be trusted.
    const std::string reason = absl::StrCat("spot check: ", kMaxSpotCheckOpinions,
                                            " workers gave as many different answers");
    jobs::AnalysisRecord failed;
    failed.request_id = request_id;
    failed.x_scaled = record->x_scaled;
    failed.failure = spec::AnalysisFailure::Of(spec::FailureKind::kService, reason);
    absl::StatusOr<jobs::AnalysisRecord> taken = entry.job->Intake(std::move(failed));
    if (!taken.ok()) return taken.status();
    *record = *std::move(taken);
    entry.opinions.erase(request_id);
    (void)store_->AddEvent(entry.row.id, "spot check", absl::StrCat("analysis ", request_id, ": ", reason));
    return false;
  }
  if (opinions.empty() && !scheduler_->HasLiveWorkerBesides(answered)) {
    // No other worker to ask: taken unchecked rather than left waiting.
    entry.opinions.erase(request_id);
    return false;
  }
  const absl::Status asked = scheduler_->AskAnotherWorker(report.worker_id, report.task_id);
  if (!asked.ok()) {
    if (opinions.empty()) entry.opinions.erase(request_id);
    return asked;
  }
  if (!opinions.empty()) {
    std::vector<std::string> differing;
    for (const SpotCheckOpinion& opinion : opinions) {
      differing.push_back(WorkerNamed(opinion.record.worker, opinion.record.holder));
    }
    differing.push_back(WorkerNamed(record->worker, record->holder));
    (void)store_->AddEvent(entry.row.id, "spot check",
                           absl::StrCat("analysis ", request_id, ": the answers of ", absl::StrJoin(differing, " and "),
                                        " differ; another worker decides"));
  }
  opinions.push_back(SpotCheckOpinion{*record, report.worker_id});
  return true;
}

bool JobManager::TakeHeldAnswerLocked(Entry& entry, const scheduler::FinishedTask& task) {
  auto held = entry.opinions.find(task.request_id);
  if (held == entry.opinions.end()) return false;
  // The second opinion could not be had (its attempts failed): the first
  // answer is taken unchecked rather than replaced by a failure.
  jobs::AnalysisRecord record = held->second.front().record;
  entry.opinions.erase(held);
  record.attempts = task.attempts;
  (void)store_->AddEvent(entry.row.id, "spot check",
                         absl::StrCat("analysis ", task.request_id, " taken unchecked: ", task.failure_reason));
  absl::Status delivered = DeliverLocked(entry, {std::move(record)});
  if (!delivered.ok()) std::cerr << "mbopt-server: job " << entry.row.id << ": " << delivered << std::endl;
  return true;
}

void JobManager::QuarantineContradicted(const std::vector<Contradicted>& liars) {
  for (const Contradicted& liar : liars) {
    std::optional<std::vector<scheduler::FinishedTask>> given_up = scheduler_->Quarantine(liar.worker_id);
    const std::string who = WorkerNamed(liar.public_id, liar.holder);
    const std::string what = absl::StrCat("its answer to analysis ", liar.request_id, " of job ", liar.job_id,
                                          " differs, bit for bit, from that of ", liar.agreed_by, ", which agree");
    if (given_up.has_value()) {
      std::cerr << "mbopt-server: WARNING: worker " << who << " QUARANTINED: " << what
                << "; it gets no tasks and its results are refused from now on"
                << (liar.holder.empty() ? "" : "; revoke its token if it cannot be trusted") << std::endl;
    }
    std::vector<std::shared_ptr<Entry>> entries;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const auto& [id, entry] : jobs_) entries.push_back(entry);
    }
    for (const std::shared_ptr<Entry>& entry : entries) {
      std::lock_guard<std::mutex> lock(entry->mutex);
      // Its answers waiting for a second opinion are dropped: the analysis
      // is answered again by the others.
      std::int64_t dropped = 0;
      for (auto it = entry->opinions.begin(); it != entry->opinions.end();) {
        std::vector<SpotCheckOpinion>& opinions = it->second;
        const std::size_t before = opinions.size();
        std::erase_if(opinions, [&](const SpotCheckOpinion& o) { return o.worker_id == liar.worker_id; });
        dropped += static_cast<std::int64_t>(before - opinions.size());
        it = opinions.empty() ? entry->opinions.erase(it) : std::next(it);
      }
      // Its unchecked answers that a running job took are taken back with
      // everything that followed them, and computed again by the others.
      std::size_t kept_records = 0;
      absl::StatusOr<std::int64_t> taken_back = RecomputeUncheckedLocked(*entry, liar.public_id, &kept_records);
      if (!taken_back.ok()) {
        std::cerr << "mbopt-server: job " << entry->row.id << ": " << taken_back.status() << std::endl;
      }
      const std::int64_t recomputed = taken_back.value_or(0);
      if (entry->row.id != liar.job_id && dropped == 0 && recomputed == 0) continue;
      std::string message = absl::StrCat("worker ", who, " quarantined: ", what);
      if (dropped > 0) absl::StrAppend(&message, "; ", dropped, " of its answers here are asked of other workers");
      if (recomputed > 0) {
        absl::StrAppend(&message, "; its unchecked answers here are taken back: the job goes back to its first ",
                        kept_records, " records and computes ", recomputed, " analyses again");
      }
      (void)store_->AddEvent(entry->row.id, "quarantined", message);
    }
    if (given_up.has_value()) {
      for (const scheduler::FinishedTask& task : *given_up) GiveUp(task);
    }
  }
}

}  // namespace mbopt::jobs::manager
