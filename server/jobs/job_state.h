// The life of a job on the server. Names are what the database stores and
// what users see; the numbering follows mbopt.v1.JobState.
#pragma once

#include <optional>
#include <string>

#include "server/slp/slp_optimizer.h"

namespace mbopt::jobs {

enum class JobState {
  kQueued = 1,
  kRunning = 2,
  kConverged = 3,
  kMaxCycles = 4,
  kStalled = 5,
  kFailed = 6,
  kCancelled = 7,
  kInterrupted = 8,  // the server stopped while it ran; it resumes on the next start
  kCompleted = 9,    // every design of a design set (sweep or sample) was analysed
};

const char* JobStateName(JobState state);  // "RUNNING", ...
std::optional<JobState> ParseJobState(const std::string& name);

// The run ended by itself (converged, max cycles, stalled, failed; a
// design set completed).
bool IsFinished(JobState state);
// Resume may continue the job (interrupted or cancelled).
bool IsResumable(JobState state);

// The job state for an optimizer's run state.
JobState JobStateOf(slp::RunState state);

}  // namespace mbopt::jobs
