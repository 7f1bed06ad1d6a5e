#include "worker/service/task_evaluator.h"

#include <cmath>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "spec/io/study_io.h"
#include "worker/engine/analysis.h"
#include "worker/engine/study_sensitivities.h"
#include "worker/engine/study_values.h"

namespace mbopt::worker {
namespace {

void Fail(v1::TaskResult* result, std::string reason) {
  result->set_ok(false);
  result->set_failure_reason(std::move(reason));
  result->clear_objective_terms();
  result->clear_constraint_values();
  result->clear_objective_gradients();
  result->clear_constraint_gradients();
}

// Row-major into `out`; false (and `out` left partly filled) at the first
// non-finite entry, whose position goes to `where`.
bool AppendFinite(const std::vector<std::vector<double>>& rows, google::protobuf::RepeatedField<double>* out,
                  std::string* where) {
  for (size_t r = 0; r < rows.size(); ++r) {
    for (size_t c = 0; c < rows[r].size(); ++c) {
      if (!std::isfinite(rows[r][c])) {
        *where = absl::StrCat("(", r, ", ", c, ") is ", rows[r][c]);
        return false;
      }
      out->Add(rows[r][c]);
    }
  }
  return true;
}

bool HasShape(const std::vector<std::vector<double>>& rows, size_t num_rows, size_t num_cols) {
  if (rows.size() != num_rows) return false;
  for (const auto& row : rows) {
    if (row.size() != num_cols) return false;
  }
  return true;
}

// Fills the result's gradients from the engine's (`num_terms` x n and
// `num_rows` x n), or says why there are none.
void SetGradients(size_t num_terms, size_t num_rows, size_t n, const engine::StudyAnalysisWithGradients& analysis,
                  v1::TaskResult* result) {
  if (!analysis.gradients.has_value()) {
    result->set_gradients_unavailable(analysis.gradients_unavailable.empty() ? "the engine gave no gradients"
                                                                             : analysis.gradients_unavailable);
    return;
  }
  if (!HasShape(analysis.gradients->objective_terms, num_terms, n) ||
      !HasShape(analysis.gradients->constraint_rows, num_rows, n)) {
    result->set_gradients_unavailable(absl::StrCat("the engine's gradients are not ", num_terms, " x ", n,
                                                   " and ", num_rows, " x ", n));
    return;
  }
  std::string where;
  if (!AppendFinite(analysis.gradients->objective_terms, result->mutable_objective_gradients(), &where)) {
    result->clear_objective_gradients();
    result->set_gradients_unavailable(absl::StrCat("objective gradient entry ", where));
    return;
  }
  if (!AppendFinite(analysis.gradients->constraint_rows, result->mutable_constraint_gradients(), &where)) {
    result->clear_objective_gradients();
    result->clear_constraint_gradients();
    result->set_gradients_unavailable(absl::StrCat("constraint gradient entry ", where));
  }
}

}  // namespace

absl::StatusOr<std::shared_ptr<const PreparedStudy>> PrepareStudy(const v1::Study& study,
                                                                  const std::string& job_id) {
  auto prepared = std::make_shared<PreparedStudy>();
  auto converted = spec::io::StudyFromProto(study, "job " + job_id);
  if (!converted.ok()) return converted.status();
  prepared->study = *std::move(converted);
  auto layout = spec::MakeStudyLayout(prepared->study);
  if (!layout.ok()) return layout.status();
  prepared->layout = *std::move(layout);
  return std::shared_ptr<const PreparedStudy>(std::move(prepared));
}

void EvaluateTask(const PreparedStudy& prepared, const v1::AnalysisTask& task,
                  v1::TaskResult* result) {
  const spec::Study& study = prepared.study;
  const std::vector<double> x(task.x_scaled().begin(), task.x_scaled().end());
  if (x.size() != study.variables.size()) {
    Fail(result, absl::StrCat("task has ", x.size(), " design variables, the study ",
                              study.variables.size()));
    return;
  }
  for (size_t i = 0; i < x.size(); ++i) {
    if (!std::isfinite(x[i])) {
      Fail(result, absl::StrCat("design variable ", study.variables[i].name, " is not finite"));
      return;
    }
  }
  // With gradients the engine integrates the sensitivity equations along
  // with the motion (worker/engine/study_sensitivities.h); whether a task
  // asks for them is fixed by its request, so an analysis is still a pure
  // function of the task.
  engine::StudyAnalysisWithGradients analysis;
  if (task.want_gradients()) {
    analysis = engine::AnalyzeStudyWithGradients(study, prepared.layout, x);
  } else {
    analysis.report = engine::Analyze(study.scene, study.ParameterValuesAt(x));
  }
  const engine::AnalysisReport& report = analysis.report;
  auto* counters = result->mutable_counters();
  counters->set_time_steps(report.counters.time_steps);
  counters->set_rhs_evaluations(report.counters.rhs_evaluations);
  counters->set_jacobian_evaluations(report.counters.jacobian_evaluations);
  counters->set_newton_iterations(report.counters.newton_iterations);
  counters->set_position_solves(report.counters.position_solves);
  counters->set_wall_seconds(report.counters.wall_seconds);
  result->set_formulation(engine::FormulationName(report.formulation));
  if (report.status != engine::AnalysisStatus::kOk) {
    Fail(result, report.failure_reason.empty() ? "analysis failed" : report.failure_reason);
    return;
  }
  auto values = engine::ComputeStudyValues(study, prepared.layout, report);
  if (!values.ok()) {
    Fail(result, std::string(values.status().message()));
    return;
  }
  for (size_t k = 0; k < values->objective_terms.size(); ++k) {
    if (!std::isfinite(values->objective_terms[k])) {
      Fail(result, absl::StrCat("objective term ", k, " is not finite (",
                                values->objective_terms[k], ")"));
      return;
    }
  }
  for (size_t h = 0; h < values->constraint_values.size(); ++h) {
    if (!std::isfinite(values->constraint_values[h])) {
      Fail(result, absl::StrCat("constraint row ", prepared.layout.rows[h].name,
                                " is not finite (", values->constraint_values[h], ")"));
      return;
    }
  }
  result->set_ok(true);
  result->clear_failure_reason();
  result->mutable_objective_terms()->Assign(values->objective_terms.begin(),
                                            values->objective_terms.end());
  result->mutable_constraint_values()->Assign(values->constraint_values.begin(),
                                              values->constraint_values.end());
  if (task.want_gradients()) {
    SetGradients(values->objective_terms.size(), values->constraint_values.size(), x.size(), analysis, result);
  }
}

}  // namespace mbopt::worker
