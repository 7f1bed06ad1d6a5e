#include "tests/testing/local_run/in_process_evaluator.h"

#include <utility>

#include "absl/strings/str_cat.h"
#include "common/monotonic_clock.h"
#include "worker/budget/analysis_budget.h"
#include "worker/engine/evaluate_study.h"

namespace mbopt::local_run {
namespace {

// Row-major, as the service carries gradients.
std::vector<double> RowMajor(const std::vector<std::vector<double>>& rows) {
  std::vector<double> flat;
  for (const auto& row : rows) flat.insert(flat.end(), row.begin(), row.end());
  return flat;
}

}  // namespace

std::vector<jobs::AnalysisRecord> InProcessEvaluator::Evaluate(const std::vector<slp::AnalysisRequest>& batch) {
  std::vector<jobs::AnalysisRecord> records;
  records.reserve(batch.size());
  for (const slp::AnalysisRequest& request : batch) records.push_back(EvaluateOne(request));
  return records;
}

jobs::AnalysisRecord InProcessEvaluator::EvaluateOne(const slp::AnalysisRequest& request) {
  jobs::AnalysisRecord record;
  record.request_id = request.id;
  record.x_scaled.assign(request.x.data(), request.x.data() + request.x.size());
  if (inject_) {
    if (std::optional<std::string> injected = inject_(request); injected.has_value()) {
      record.failure = spec::AnalysisFailure::Of(spec::FailureKind::kInjected, absl::StrCat("injected: ", *injected));
      return record;
    }
  }
  absl::StatusOr<engine::StudyEvaluation> evaluation =
      engine::EvaluateStudy(study_, layout_, record.x_scaled, request.want_gradients, nullptr,
                            budget::AnalysisBudget(&MonotonicSeconds, nullptr));
  if (!evaluation.ok()) {
    // The request does not fit the study: the job's intake would refuse
    // nothing here, so it is reported as the service would report it.
    record.failure = spec::AnalysisFailure::Of(spec::FailureKind::kService, std::string(evaluation.status().message()));
    return record;
  }
  ++analyses_run_;
  total_counters_ += evaluation->counters;
  record.counters = evaluation->counters;
  record.failure = evaluation->failure;
  if (!evaluation->ok()) return record;
  record.objective_terms = evaluation->values->objective_terms;
  record.constraint_values = evaluation->values->constraint_values;
  if (evaluation->gradients.has_value()) {
    record.objective_gradients = RowMajor(evaluation->gradients->objective_terms);
    record.constraint_gradients = RowMajor(evaluation->gradients->constraint_rows);
  } else {
    record.gradients_unavailable = evaluation->gradients_unavailable;
  }
  return record;
}

}  // namespace mbopt::local_run
