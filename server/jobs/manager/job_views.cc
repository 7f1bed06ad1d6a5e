// The job manager's summaries and views of its jobs (Get, List, Watch's
// waits), and the bookkeeping of which jobs are in memory.
#include <algorithm>
#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/status_macros.h"
#include "server/jobs/manager/job_entry.h"
#include "server/jobs/manager/job_manager.h"
#include "server/jobs/job_result.h"
#include "server/jobs/problem_from_study.h"

namespace mbopt::jobs::manager {

using jobs::JobState;

double JobManager::WallSecondsLocked(const Entry& entry) const {
  double wall = entry.wall_before_s;
  if (entry.timing) wall += static_cast<double>(clock_->NowMs() - entry.run_started_ms) / 1000.0;
  return wall;
}

JobSummaryData JobManager::SummaryLocked(const Entry& entry) const {
  if (!entry.resident) {
    JobSummaryData s = entry.stopped_summary;
    s.state = entry.state;
    s.message = entry.message;
    s.wall_seconds = WallSecondsLocked(entry);
    return s;
  }
  JobSummaryData s;
  s.job_id = entry.row.id;
  s.study_name = entry.row.study_name;
  s.owner = entry.row.owner;
  s.state = entry.state;
  s.message = entry.message;
  if (entry.state == JobState::kQueued) {
    std::lock_guard<std::mutex> admission_lock(admission_mutex_);
    s.message = admission_.WhyWaiting(entry.row.id);
  }
  s.created_unix_ms = entry.row.created_unix_ms;
  s.wall_seconds = WallSecondsLocked(entry);
  s.cycles = entry.row.cycles;
  s.analyses = entry.row.analyses;
  Eigen::VectorXd design;
  std::optional<slp::SlpOptions> options;
  if (entry.study_ok) {
    s.objective_unit = spec::ReportedObjectiveUnit(*entry.study);
    if (entry.job != nullptr) {
      options = entry.job->options();
    } else if (absl::StatusOr<slp::SlpOptions> from_study = jobs::SlpOptionsFromStudy(*entry.study);
               from_study.ok()) {
      options = *from_study;
    }
    if (options.has_value()) s.max_cycles = options->max_cycles;
    // A design set's records are its designs: progress is designs done of all.
    if (!entry.study->design_set.empty()) {
      s.design_set = true;
      s.max_cycles = static_cast<int>(entry.study->design_set.size());
    }
    // A Pareto front's records are its points, one each.
    if (entry.study->pareto.enabled()) {
      s.design_set = true;
      s.pareto = true;
      s.max_cycles = entry.study->pareto.total_points();
    }
    design.resize(static_cast<Eigen::Index>(entry.study->variables.size()));
    for (size_t i = 0; i < entry.study->variables.size(); ++i) {
      const spec::DesignVariable& v = entry.study->variables[i];
      s.design_names.push_back(v.name);
      s.design_units.push_back(v.parameter >= 0 && static_cast<size_t>(v.parameter) < entry.study->scene.parameters.size()
                                   ? entry.study->scene.parameters[static_cast<size_t>(v.parameter)].unit
                                   : "");
      design[static_cast<Eigen::Index>(i)] = v.initial;
    }
  }
  s.failed_analyses_by_kind = entry.failed_analyses_by_kind;
  if (entry.state == JobState::kRunning && entry.study_ok) {
    if (const scheduler::TaskNeeds needs = NeedsOf(*entry.study); !scheduler_->SomeWorkerCan(needs)) {
      s.waiting_for = absl::StrCat("no registered worker declares ", needs.Describe(),
                                   ": its analyses wait for one (mbopt workers)");
    }
  }
  // The optimizer minimizes; a maximized value is reported as itself.
  const double sign = entry.study_ok ? entry.study->objective.ReportedSign() : 1.0;
  if (entry.job != nullptr) {
    const jobs::Job& job = *entry.job;
    s.cycles = job.cycles_completed();
    s.analyses = job.analyses_used();
    for (const auto& [kind, count] : entry.job->failures_by_kind()) {
      s.failed_analyses_by_kind[spec::FailureKindName(kind)] = count;
    }
    if (!entry.records.empty()) {
      // A design set's best design is the best of its analysed designs.
      const std::optional<slp::DesignPoint> best =
          job.is_design_set() ? jobs::BestDesignOfRecords(entry.records) : job.optimizer().best_design();
      if (best.has_value()) {
        design = best->x;
        s.objective = sign * best->objective;
        s.max_violation = best->max_violation;
      }
    }
  } else if (!entry.records.empty()) {
    // Not running in this process: the same choice from the logged records.
    if (std::optional<slp::DesignPoint> best = jobs::BestDesignOfRecords(entry.records)) {
      design = best->x;
      s.objective = sign * best->objective;
      s.max_violation = best->max_violation;
    }
  }
  if (entry.study_ok && static_cast<size_t>(design.size()) == entry.study->variables.size()) {
    for (size_t i = 0; i < entry.study->variables.size(); ++i) {
      s.design.push_back(entry.study->variables[i].scale * design[static_cast<Eigen::Index>(i)]);
    }
  }
  return s;
}

JobView JobManager::ViewLocked(const Entry& entry, std::size_t first_record, JobViewFor view_for) const {
  JobView view;
  view.summary = SummaryLocked(entry);
  view.first_record = std::min(first_record, entry.records.size());
  view.records.assign(entry.records.begin() + static_cast<std::ptrdiff_t>(view.first_record), entry.records.end());
  view.version = entry.version;
  view.ended = !Running(entry.state);
  if (entry.study_ok) {
    view.layout = entry.layout;
    for (const spec::DesignVariable& v : entry.study->variables) view.variable_scales.push_back(v.scale);
    view.objective_sign = entry.study->objective.ReportedSign();
    const spec::Study& study = *entry.study;
    if (study.pareto.enabled()) {
      view.pareto_far_end = study.pareto.three_objectives() ? 2 : study.pareto.points;
      // The scale of the traded rows (the first's: they share it), by
      // which a far end's run divides the objective it minimizes.
      auto traded_scale = [&](int constraint) {
        if (entry.layout == nullptr) return 1.0;
        for (const spec::ConstraintRow& row : entry.layout->rows) {
          if (row.constraint == constraint) return row.scale;
        }
        return 1.0;
      };
      view.pareto_three = study.pareto.three_objectives();
      if (view.pareto_three && static_cast<size_t>(study.pareto.third_constraint) < study.constraints.size()) {
        view.pareto_third_shown_factor =
            1.0 / study.constraints[static_cast<size_t>(study.pareto.third_constraint)].si_per_unit;
        view.pareto_third_end_factor = view.pareto_third_shown_factor * traded_scale(study.pareto.third_constraint);
      }
      if (study.pareto.trades_objective) {
        view.pareto_shown_factor = study.second_objective.ReportedSign();
      } else if (study.pareto.constraint >= 0 && static_cast<size_t>(study.pareto.constraint) < study.constraints.size()) {
        view.pareto_shown_factor = 1.0 / study.constraints[static_cast<size_t>(study.pareto.constraint)].si_per_unit;
      }
      view.pareto_far_end_factor =
          view.pareto_shown_factor *
          traded_scale(study.pareto.trades_objective ? spec::kSecondObjectiveRow : study.pareto.constraint);
    }
  }
  if (view_for == JobViewFor::kReader) view.study_bytes = entry.row.study;
  return view;
}

absl::StatusOr<JobView> JobManager::Get(const std::string& job_id, std::size_t first_record,
                                        JobViewFor view_for) {
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<Entry> entry, Find(job_id));
  std::lock_guard<std::mutex> lock(entry->mutex);
  return RestoredViewLocked(*entry, first_record, view_for);
}

absl::StatusOr<JobView> JobManager::RestoredViewLocked(Entry& entry, std::size_t first_record,
                                                       JobViewFor view_for) {
  MBOPT_RETURN_IF_ERROR(RestoreLocked(entry));
  JobView view = ViewLocked(entry, first_record, view_for);
  EvictLocked(entry);
  return view;
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
  std::sort(ordered.begin(), ordered.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<JobSummaryData> summaries;
  for (auto& [seq, summary] : ordered) summaries.push_back(std::move(summary));
  return summaries;
}

absl::StatusOr<std::string> JobManager::OwnerOf(const std::string& job_id) {
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<Entry> entry, Find(job_id));
  std::lock_guard<std::mutex> lock(entry->mutex);
  return entry->row.owner;
}

absl::StatusOr<JobView> JobManager::WaitForChange(const std::string& job_id, std::size_t first_record,
                                                  std::int64_t version_seen, std::int64_t max_wait_ms) {
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<Entry> entry, Find(job_id));
  std::unique_lock<std::mutex> lock(entry->mutex);
  // A real-time wait: watchers are people, not the job's clock.
  entry->changed.wait_for(lock, std::chrono::milliseconds(std::max<std::int64_t>(0, max_wait_ms)),
                          [&] { return entry->version != version_seen; });
  return RestoredViewLocked(*entry, first_record, JobViewFor::kWatcher);
}

absl::Status JobManager::StartWatching(const std::string& job_id) {
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<Entry> entry, Find(job_id));
  std::lock_guard<std::mutex> lock(entry->mutex);
  entry->watchers += 1;
  return absl::OkStatus();
}

void JobManager::StopWatching(const std::string& job_id) {
  absl::StatusOr<std::shared_ptr<Entry>> entry = Find(job_id);
  if (!entry.ok()) return;
  std::lock_guard<std::mutex> lock((*entry)->mutex);
  (*entry)->watchers -= 1;
  EvictLocked(**entry);
}

std::size_t JobManager::ResidentJobs() {
  std::vector<std::shared_ptr<Entry>> entries;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [id, entry] : jobs_) entries.push_back(entry);
  }
  std::size_t resident = 0;
  for (const auto& entry : entries) {
    std::lock_guard<std::mutex> lock(entry->mutex);
    if (entry->resident) ++resident;
  }
  return resident;
}

absl::StatusOr<std::string> JobManager::StudyBytes(const std::string& job_id) {
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<Entry> entry, Find(job_id));
  std::lock_guard<std::mutex> lock(entry->mutex);
  if (!entry->resident) {
    MBOPT_ASSIGN_OR_RETURN(store::JobRow row, store_->GetJob(job_id));
    return row.study;
  }
  return entry->row.study;
}

absl::StatusOr<std::vector<store::AnalysesByHolder>> JobManager::ComputedBy(const std::string& job_id) {
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<Entry> entry, Find(job_id));
  return store_->CountAnalysesByHolder(entry->row.id);
}

}  // namespace mbopt::jobs::manager
