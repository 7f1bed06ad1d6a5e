// A job as the job manager holds it (JobManager::Entry), and the small
// rules its parts share; private to server/jobs/manager (job_manager.cc:
// submission, results, states; job_views.cc: summaries and views).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "server/jobs/job.h"
#include "server/jobs/job_state.h"
#include "server/jobs/manager/job_manager.h"
#include "server/jobs/manager/spot_check.h"
#include "server/scheduler/scheduler.h"
#include "server/store/store.h"
#include "spec/layout.h"
#include "spec/study.h"

namespace mbopt::jobs::manager {

struct JobManager::Entry {
  std::mutex mutex;
  std::condition_variable changed;

  store::JobRow row;  // id, names, study bytes, created; progress as loaded
  jobs::JobState state = jobs::JobState::kQueued;
  std::string message;

  bool study_ok = false;
  // Decoded once, shared with the job's optimizer (never null; empty while
  // not resident or not decodable). The bytes as submitted are row.study.
  std::shared_ptr<const spec::Study> study = std::make_shared<const spec::Study>();
  // While resident; shared with the job and with views, never copied.
  std::shared_ptr<const spec::StudyLayout> layout;
  std::unique_ptr<jobs::Job> job;  // the optimizer of the current run; none once it stopped
  // Spot checks: answers held until another worker's agrees, by request id
  // (of the current run).
  std::map<std::int64_t, std::vector<SpotCheckOpinion>> opinions;
  // Failed analyses by kind, kept when the optimizer is released.
  std::map<std::string, std::int64_t> failed_analyses_by_kind;

  std::vector<slp::CycleRecord> records;  // published: durable as the store's level promises
  // Committed without a sync, by the number of their commit: published once
  // the log is synced.
  std::deque<std::pair<std::int64_t, std::vector<slp::CycleRecord>>> unsynced;
  std::int64_t version = 0;

  // Whether the study, its bytes and the records are in memory. A stopped
  // job keeps only its summary (stopped_summary); views read the rest from
  // the database on demand (RestoreLocked), so the server's memory does not
  // grow with the number of finished jobs.
  bool resident = true;
  JobSummaryData stopped_summary;
  int watchers = 0;  // watch streams open on the job: it stays resident for them

  double wall_before_s = 0;  // running time of earlier runs
  bool timing = false;
  std::int64_t run_started_ms = 0;
};

// Whether the job may still change: running, or queued to run.
inline bool Running(jobs::JobState state) {
  return state == jobs::JobState::kRunning || state == jobs::JobState::kQueued;
}

// What a worker must be able to do to run the study's analyses.
inline scheduler::TaskNeeds NeedsOf(const spec::Study& study) {
  scheduler::TaskNeeds needs;
  if (const auto* external = std::get_if<spec::ExternalModel>(&study.scene.model)) needs.driver = external->driver;
  if (const auto* fmu = std::get_if<spec::FmuModel>(&study.scene.model)) {
    needs.loads_fmus = true;
    needs.fmu_platforms = fmu->platforms;
  }
  return needs;
}

}  // namespace mbopt::jobs::manager
