// Runs an SlpOptimizer to its end in memory against an evaluator function,
// for the core's own tests on analytic problems: they test the core alone.
// Studies are driven by jobs::Job only (server/jobs/job.h).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "absl/status/statusor.h"
#include "server/slp/slp_optimizer.h"

namespace mbopt::slp {

// Computes the analysis of one request. The driver fills in request_id. Must
// not throw; a failed analysis is AnalysisOutcome::kFailed.
using Evaluator = std::function<AnalysisResult(const AnalysisRequest&)>;

struct RunToCompletionOptions {
  // Guard against a run that never ends: ResourceExhausted past this.
  std::int64_t max_analyses = 1'000'000;
  // Optional: permutes each batch of results before submission (results of a
  // batch may arrive in any order; tests use this to prove it).
  std::function<void(std::vector<AnalysisResult>&)> reorder_batch;
};

struct RunOutcome {
  RunState state = RunState::kRunning;
  std::vector<CycleRecord> records;
  Eigen::VectorXd design;  // scaled
  double objective = 0;
  double max_violation = 0;
  int cycles = 0;
  std::int64_t analyses = 0;
  std::vector<AnalysisResult> results;  // every result submitted, in order
};

absl::StatusOr<RunOutcome> RunToCompletion(SlpOptimizer& optimizer, const Evaluator& evaluate,
                                           const RunToCompletionOptions& options = {});

}  // namespace mbopt::slp
