#include "worker/service/task_evaluator.h"

#include <string>
#include <variant>
#include <vector>

#include "common/packed_doubles/packed_doubles.h"
#include "spec/io/analysis_outcome_convert.h"
#include "spec/io/study_io.h"
#include "worker/engine/evaluate_study.h"

namespace mbopt::worker {
namespace {

void Fail(v1::TaskResult* result, spec::FailureKind kind, std::string reason) {
  result->set_ok(false);
  result->set_failure_kind(spec::io::FailureKindToProto(kind));
  result->set_failure_reason(std::move(reason));
  result->clear_objective_terms();
  result->clear_constraint_values();
  result->clear_objective_terms_packed();
  result->clear_constraint_values_packed();
  result->clear_objective_gradients();
  result->clear_constraint_gradients();
}

// Row-major, one row per value, one column per design variable.
void AppendRowMajor(const std::vector<std::vector<double>>& rows, google::protobuf::RepeatedField<double>* out) {
  for (const auto& row : rows) out->Add(row.begin(), row.end());
}

}  // namespace

std::string CannotRun(const spec::Study& study, const external::ExternalWorkerSettings* external) {
  const auto* model = std::get_if<spec::ExternalModel>(&study.scene.model);
  if (model == nullptr) return "";
  if (external == nullptr) {
    return "the study's scene is external (driver \"" + model->driver +
           "\") and this worker declares no drivers (mbopt-worker --drivers FILE)";
  }
  if (external::FindDriver(external->drivers, model->driver) != nullptr) return "";
  std::string names;
  for (const external::DriverDeclaration& d : external->drivers) names += (names.empty() ? "\"" : ", \"") + d.name + "\"";
  return "this worker declares no driver \"" + model->driver + "\"; it declares: " + names;
}

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

void EvaluateTask(const PreparedStudy& prepared, const v1::AnalysisTask& task, ValueEncoding encoding,
                  v1::TaskResult* result, const engine::ExternalAnalyzer* external,
                  const budget::AnalysisBudget& budget) {
  const std::vector<double> x(task.x_scaled().begin(), task.x_scaled().end());
  absl::StatusOr<engine::StudyEvaluation> evaluation =
      engine::EvaluateStudy(prepared.study, prepared.layout, x, task.want_gradients(), external, budget);
  if (!evaluation.ok()) {
    // The task does not fit the study (or the engine's outputs do not fit
    // the layout): nothing about the design point, so the service's kind.
    Fail(result, spec::FailureKind::kService, std::string(evaluation.status().message()));
    return;
  }
  spec::io::CountersToProto(evaluation->counters, result->mutable_counters());
  result->set_formulation(spec::FormulationName(evaluation->formulation));
  if (!evaluation->ok()) {
    Fail(result, evaluation->failure.kind, evaluation->failure.reason);
    return;
  }
  const spec::StudyValues& values = *evaluation->values;
  result->set_ok(true);
  result->clear_failure_reason();
  result->set_failure_kind(v1::ANALYSIS_FAILURE_KIND_UNSPECIFIED);
  result->clear_objective_terms();
  result->clear_constraint_values();
  result->clear_objective_terms_packed();
  result->clear_constraint_values_packed();
  if (encoding == ValueEncoding::kPacked) {
    result->set_objective_terms_packed(packed::PackDoubles(values.objective_terms));
    result->set_constraint_values_packed(packed::PackDoubles(values.constraint_values));
  } else {
    result->mutable_objective_terms()->Assign(values.objective_terms.begin(), values.objective_terms.end());
    result->mutable_constraint_values()->Assign(values.constraint_values.begin(), values.constraint_values.end());
  }
  if (!task.want_gradients()) return;
  if (evaluation->gradients.has_value()) {
    AppendRowMajor(evaluation->gradients->objective_terms, result->mutable_objective_gradients());
    AppendRowMajor(evaluation->gradients->constraint_rows, result->mutable_constraint_gradients());
  } else {
    result->set_gradients_unavailable(evaluation->gradients_unavailable);
  }
}

}  // namespace mbopt::worker
