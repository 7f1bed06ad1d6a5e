#include "server/local_run/evaluate_design.h"

#include <cmath>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/status_macros.h"
#include "worker/engine/study_sensitivities.h"
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

absl::Status CheckSize(const spec::Study& study, const Eigen::VectorXd& x_scaled) {
  if (x_scaled.size() != static_cast<Eigen::Index>(study.variables.size())) {
    return absl::InvalidArgumentError(absl::StrCat("design has ", x_scaled.size(), " values, study ",
                                                   study.name, " has ", study.variables.size(),
                                                   " variables"));
  }
  return absl::OkStatus();
}

// The evaluation of one engine report.
absl::StatusOr<DesignEvaluation> FromReport(const spec::Study& study,
                                            const spec::StudyLayout& layout,
                                            const engine::AnalysisReport& report) {
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

bool AllFinite(const std::vector<std::vector<double>>& rows) {
  for (const auto& row : rows) {
    for (double v : row) {
      if (!std::isfinite(v)) return false;
    }
  }
  return true;
}

Eigen::MatrixXd ToMatrix(const std::vector<std::vector<double>>& rows, Eigen::Index cols) {
  Eigen::MatrixXd m(static_cast<Eigen::Index>(rows.size()), cols);
  for (size_t r = 0; r < rows.size(); ++r) {
    for (Eigen::Index c = 0; c < cols; ++c) m(static_cast<Eigen::Index>(r), c) = rows[r][static_cast<size_t>(c)];
  }
  return m;
}

}  // namespace

absl::StatusOr<DesignEvaluation> EvaluateDesign(const spec::Study& study,
                                                const spec::StudyLayout& layout,
                                                const Eigen::VectorXd& x_scaled) {
  MBOPT_RETURN_IF_ERROR(CheckSize(study, x_scaled));
  const std::vector<double> x(x_scaled.data(), x_scaled.data() + x_scaled.size());
  return FromReport(study, layout, engine::Analyze(study.scene, study.ParameterValuesAt(x)));
}

absl::StatusOr<DesignEvaluation> EvaluateDesignWithGradients(const spec::Study& study,
                                                             const spec::StudyLayout& layout,
                                                             const Eigen::VectorXd& x_scaled) {
  MBOPT_RETURN_IF_ERROR(CheckSize(study, x_scaled));
  const std::vector<double> x(x_scaled.data(), x_scaled.data() + x_scaled.size());
  engine::StudyAnalysisWithGradients analysis = engine::AnalyzeStudyWithGradients(study, layout, x);
  MBOPT_ASSIGN_OR_RETURN(DesignEvaluation evaluation, FromReport(study, layout, analysis.report));
  evaluation.gradients_unavailable = analysis.gradients_unavailable;
  if (evaluation.ok() && analysis.gradients.has_value()) {
    if (AllFinite(analysis.gradients->objective_terms) && AllFinite(analysis.gradients->constraint_rows)) {
      evaluation.gradients = std::move(analysis.gradients);
    } else {
      evaluation.gradients_unavailable = "non-finite gradient";
    }
  }
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
  if (evaluation.gradients.has_value()) {
    const auto cols = static_cast<Eigen::Index>(
        evaluation.gradients->objective_terms.empty() ? 0 : evaluation.gradients->objective_terms[0].size());
    result.objective_gradients = ToMatrix(evaluation.gradients->objective_terms, cols);
    result.constraint_gradients = ToMatrix(evaluation.gradients->constraint_rows, cols);
  }
  return result;
}

}  // namespace mbopt::local_run
