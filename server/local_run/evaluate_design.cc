#include "server/local_run/evaluate_design.h"

#include <cmath>
#include <vector>

#include "absl/strings/str_cat.h"
#include "worker/engine/study_values.h"

namespace mbopt::local_run {
namespace {

// Names the first non-finite study value, or returns "" if all are finite.
std::string FirstNonFinite(const spec::StudyLayout& layout, const spec::StudyValues& values) {
  for (size_t j = 0; j < values.objective_terms.size(); ++j) {
    if (!std::isfinite(values.objective_terms[j])) {
      return absl::StrCat("objective term ", j, " is ", values.objective_terms[j]);
    }
  }
  for (size_t h = 0; h < values.constraint_values.size(); ++h) {
    if (!std::isfinite(values.constraint_values[h])) {
      const std::string name = h < layout.rows.size() ? layout.rows[h].name : absl::StrCat("row ", h);
      return absl::StrCat("constraint ", name, " is ", values.constraint_values[h]);
    }
  }
  if (!std::isfinite(values.objective)) return absl::StrCat("objective is ", values.objective);
  return "";
}

}  // namespace

absl::StatusOr<DesignEvaluation> EvaluateDesign(const spec::Study& study,
                                                const spec::StudyLayout& layout,
                                                const Eigen::VectorXd& x_scaled) {
  if (x_scaled.size() != static_cast<Eigen::Index>(study.variables.size())) {
    return absl::InvalidArgumentError(absl::StrCat("design has ", x_scaled.size(), " values, study ",
                                                   study.name, " has ", study.variables.size(),
                                                   " variables"));
  }
  const std::vector<double> x(x_scaled.data(), x_scaled.data() + x_scaled.size());
  const engine::AnalysisReport report = engine::Analyze(study.scene, study.ParameterValuesAt(x));

  DesignEvaluation evaluation;
  evaluation.status = report.status;
  evaluation.failure_reason = report.failure_reason;
  evaluation.formulation = report.formulation;
  evaluation.counters = report.counters;
  if (report.status != engine::AnalysisStatus::kOk) {
    if (evaluation.failure_reason.empty()) evaluation.failure_reason = "analysis failed (no reason given)";
    return evaluation;
  }
  absl::StatusOr<spec::StudyValues> values = engine::ComputeStudyValues(study, layout, report);
  if (!values.ok()) return values.status();
  const std::string non_finite = FirstNonFinite(layout, *values);
  if (!non_finite.empty()) {
    evaluation.status = engine::AnalysisStatus::kFailed;
    evaluation.failure_reason = absl::StrCat("non-finite result: ", non_finite);
    return evaluation;
  }
  evaluation.values = std::move(values).value();
  return evaluation;
}

slp::AnalysisResult ToAnalysisResult(const DesignEvaluation& evaluation) {
  slp::AnalysisResult result;
  if (!evaluation.ok() || !evaluation.values.has_value()) {
    result.outcome = slp::AnalysisOutcome::kFailed;
    result.failure_reason = evaluation.failure_reason;
    return result;
  }
  const spec::StudyValues& v = *evaluation.values;
  result.outcome = slp::AnalysisOutcome::kOk;
  result.objective_terms =
      Eigen::Map<const Eigen::VectorXd>(v.objective_terms.data(), static_cast<Eigen::Index>(v.objective_terms.size()));
  result.constraint_values = Eigen::Map<const Eigen::VectorXd>(
      v.constraint_values.data(), static_cast<Eigen::Index>(v.constraint_values.size()));
  return result;
}

}  // namespace mbopt::local_run
