#include "worker/engine/evaluate_study.h"

#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/status_macros.h"
#include "worker/engine/analysis.h"
#include "worker/engine/study_sensitivities.h"
#include "worker/engine/study_values.h"

namespace mbopt::engine {
namespace {

absl::Status CheckDesign(const spec::Study& study, const std::vector<double>& x_scaled) {
  if (x_scaled.size() != study.variables.size()) {
    return absl::InvalidArgumentError(absl::StrCat("the design point has ", x_scaled.size(),
                                                   " design variables, study ", study.name, " has ",
                                                   study.variables.size()));
  }
  for (size_t i = 0; i < x_scaled.size(); ++i) {
    if (!std::isfinite(x_scaled[i])) {
      return absl::InvalidArgumentError(
          absl::StrCat("design variable ", study.variables[i].name, " is not finite (", x_scaled[i], ")"));
    }
  }
  return absl::OkStatus();
}

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
      return absl::StrCat("constraint row ", name, " is ", values.constraint_values[h]);
    }
  }
  if (!std::isfinite(values.objective)) return absl::StrCat("objective is ", values.objective);
  return "";
}

bool HasShape(const std::vector<std::vector<double>>& rows, size_t num_rows, size_t num_cols) {
  if (rows.size() != num_rows) return false;
  for (const auto& row : rows) {
    if (row.size() != num_cols) return false;
  }
  return true;
}

// "" when every entry is finite, else where the first one is not.
std::string FirstNonFiniteEntry(const char* what, const std::vector<std::vector<double>>& rows) {
  for (size_t r = 0; r < rows.size(); ++r) {
    for (size_t c = 0; c < rows[r].size(); ++c) {
      if (!std::isfinite(rows[r][c])) return absl::StrCat(what, " gradient entry (", r, ", ", c, ") is ", rows[r][c]);
    }
  }
  return "";
}

// Keeps the engine's gradients when they have the values' shape and are
// finite; otherwise says why there are none.
void TakeGradients(std::optional<spec::StudyGradients> gradients, std::string unavailable, size_t num_variables,
                   StudyEvaluation* evaluation) {
  if (!gradients.has_value()) {
    evaluation->gradients_unavailable = unavailable.empty() ? "the engine gave no gradients" : std::move(unavailable);
    return;
  }
  const size_t terms = evaluation->values->objective_terms.size();
  const size_t rows = evaluation->values->constraint_values.size();
  if (!HasShape(gradients->objective_terms, terms, num_variables) ||
      !HasShape(gradients->constraint_rows, rows, num_variables)) {
    evaluation->gradients_unavailable = absl::StrCat("the engine's gradients are not ", terms, " x ", num_variables,
                                                     " and ", rows, " x ", num_variables);
    return;
  }
  std::string where = FirstNonFiniteEntry("objective", gradients->objective_terms);
  if (where.empty()) where = FirstNonFiniteEntry("constraint", gradients->constraint_rows);
  if (!where.empty()) {
    evaluation->gradients_unavailable = std::move(where);
    return;
  }
  evaluation->gradients = std::move(gradients);
}

}  // namespace

absl::StatusOr<StudyEvaluation> EvaluateStudy(const spec::Study& study, const spec::StudyLayout& layout,
                                              const std::vector<double>& x_scaled, bool want_gradients,
                                              const ExternalAnalyzer* external,
                                              const budget::AnalysisBudget& budget) {
  MBOPT_RETURN_IF_ERROR(CheckDesign(study, x_scaled));
  // Whether gradients are computed is fixed by the request, so an
  // evaluation stays a pure function of (study, x, want_gradients).
  StudyAnalysisWithGradients analysis;
  const std::vector<double> parameters_si = study.ParameterValuesAt(x_scaled);
  if (want_gradients) {
    analysis = AnalyzeStudyWithGradients(study, layout, x_scaled, external, budget);
  } else {
    analysis.report = AnalyzeCases(study, parameters_si, external, budget);
  }
  const spec::AnalysisReport& report = analysis.report;
  StudyEvaluation evaluation;
  evaluation.failure = report.failure;
  evaluation.formulation = report.formulation;
  evaluation.counters = report.counters;
  if (!report.ok()) {
    if (evaluation.failure.reason.empty()) evaluation.failure.reason = "the analysis failed (no reason given)";
    return evaluation;
  }
  MBOPT_ASSIGN_OR_RETURN(spec::StudyValues values, ComputeStudyValues(study, layout, report, parameters_si));
  if (const std::string non_finite = FirstNonFinite(layout, values); !non_finite.empty()) {
    evaluation.failure =
        spec::AnalysisFailure::Of(spec::FailureKind::kNonFiniteValue, absl::StrCat("non-finite result: ", non_finite));
    return evaluation;
  }
  evaluation.values = std::move(values);
  if (want_gradients) {
    TakeGradients(std::move(analysis.gradients), std::move(analysis.gradients_unavailable), x_scaled.size(),
                  &evaluation);
  }
  return evaluation;
}

}  // namespace mbopt::engine
