#include "tests/slp_testing/drive_optimizer.h"

#include "absl/strings/str_cat.h"
#include "common/status_macros.h"

namespace mbopt::slp {

absl::StatusOr<RunOutcome> RunToCompletion(SlpOptimizer& optimizer, const Evaluator& evaluate,
                                           const RunToCompletionOptions& options) {
  RunOutcome out;
  while (optimizer.state() == RunState::kRunning) {
    const std::vector<AnalysisRequest> pending = optimizer.PendingRequests();
    if (pending.empty()) {
      return absl::InternalError("optimizer is running but requests no analysis");
    }
    if (optimizer.analyses_used() + static_cast<std::int64_t>(pending.size()) >
        options.max_analyses) {
      return absl::ResourceExhaustedError(
          absl::StrCat("run needs more than ", options.max_analyses, " analyses"));
    }
    std::vector<AnalysisResult> batch;
    batch.reserve(pending.size());
    for (const AnalysisRequest& request : pending) {
      AnalysisResult result = evaluate(request);
      result.request_id = request.id;
      batch.push_back(std::move(result));
    }
    if (options.reorder_batch) options.reorder_batch(batch);
    for (const AnalysisResult& result : batch) {
      MBOPT_RETURN_IF_ERROR(optimizer.SubmitResult(result));
      out.results.push_back(result);
    }
    for (CycleRecord& r : optimizer.TakeNewRecords()) out.records.push_back(std::move(r));
  }
  out.state = optimizer.state();
  const slp::DesignPoint best = optimizer.best_design();
  out.design = best.x;
  out.objective = best.objective;
  out.max_violation = best.max_violation;
  out.cycles = optimizer.cycles_completed();
  out.analyses = optimizer.analyses_used();
  return out;
}

}  // namespace mbopt::slp
