#include "worker/service/task_evaluator.h"

#include <cmath>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "spec/io/study_io.h"
#include "worker/engine/analysis.h"
#include "worker/engine/study_values.h"

namespace mbopt::worker {
namespace {

void Fail(v1::TaskResult* result, std::string reason) {
  result->set_ok(false);
  result->set_failure_reason(std::move(reason));
  result->clear_objective_terms();
  result->clear_constraint_values();
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
  const engine::AnalysisReport report = engine::Analyze(study.scene, study.ParameterValuesAt(x));
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
}

}  // namespace mbopt::worker
