#include "server/jobs/job_state.h"

namespace mbopt::jobs {

const char* JobStateName(JobState state) {
  switch (state) {
    case JobState::kQueued: return "QUEUED";
    case JobState::kRunning: return "RUNNING";
    case JobState::kConverged: return "CONVERGED";
    case JobState::kMaxCycles: return "MAX_CYCLES";
    case JobState::kStalled: return "STALLED";
    case JobState::kFailed: return "FAILED";
    case JobState::kCancelled: return "CANCELLED";
    case JobState::kInterrupted: return "INTERRUPTED";
    case JobState::kCompleted: return "COMPLETED";
  }
  return "UNKNOWN";
}

std::optional<JobState> ParseJobState(const std::string& name) {
  for (int s = 1; s <= 9; ++s) {
    if (name == JobStateName(static_cast<JobState>(s))) return static_cast<JobState>(s);
  }
  return std::nullopt;
}

bool IsFinished(JobState state) {
  return state == JobState::kConverged || state == JobState::kMaxCycles || state == JobState::kStalled ||
         state == JobState::kFailed || state == JobState::kCompleted;
}

bool IsResumable(JobState state) { return state == JobState::kInterrupted || state == JobState::kCancelled; }

JobState JobStateOf(slp::RunState state) {
  switch (state) {
    case slp::RunState::kRunning: return JobState::kRunning;
    case slp::RunState::kConverged: return JobState::kConverged;
    case slp::RunState::kMaxCycles: return JobState::kMaxCycles;
    case slp::RunState::kStalled: return JobState::kStalled;
    case slp::RunState::kFailed: return JobState::kFailed;
  }
  return JobState::kFailed;
}

}  // namespace mbopt::jobs
