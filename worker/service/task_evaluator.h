// What a worker does with one task: the scaled design point becomes scene
// parameter values, the engine analyses the scene there, and the study layout
// turns its outputs into the study values the optimizer asked for (objective
// terms and constraint values g_h, aligned with spec::MakeStudyLayout). Every
// way this can go wrong (the engine fails, a shape does not match, a value is
// NaN or infinite) becomes a result with ok = false and a reason: the
// optimizer decides what a failed analysis means.
//
// A task with want_gradients is analysed through the engine's sensitivity
// entry point (worker/engine/study_sensitivities.h) and its result carries
// the gradients of the values with respect to the scaled design variables,
// row-major. When the engine has none for the study (e.g. a design variable
// that sets an offset), or they are not finite, the result has the values
// only and gradients_unavailable says why; that is not a failed analysis.
#pragma once

#include <memory>

#include "absl/status/statusor.h"
#include "mbopt/v1/service.pb.h"
#include "spec/layout.h"
#include "spec/study.h"
#include "worker/budget/analysis_budget.h"
#include "worker/engine/external_analyzer.h"
#include "worker/external/scene_analyzer.h"

namespace mbopt::worker {

// A job's study, converted once and shared by every task of the job.
struct PreparedStudy {
  spec::Study study;
  spec::StudyLayout layout;
};

// InvalidArgument if the study (as the server sent it) does not convert.
absl::StatusOr<std::shared_ptr<const PreparedStudy>> PrepareStudy(const v1::Study& study,
                                                                  const std::string& job_id);

// Why this worker cannot run any task of `study` (an external scene whose
// driver `external` does not declare, or no drivers at all); "" when it can.
std::string CannotRun(const spec::Study& study, const external::ExternalWorkerSettings* external);

// How a result carries its values: packed (common/packed_doubles) for a
// server that reads them, as repeated doubles for an older one
// (RegisterWorkerResponse.takes_packed_values).
enum class ValueEncoding { kPacked, kUnpacked };

// Fills everything of `result` except worker_id, task_id, job_id and
// request_id. `external` runs external scenes (null: they fail). `budget`
// brings the clock and the task's cancel flag (engine::Analyze); without a
// clock the scene's time limit does not apply and the wall time is 0.
void EvaluateTask(const PreparedStudy& prepared, const v1::AnalysisTask& task, ValueEncoding encoding,
                  v1::TaskResult* result, const engine::ExternalAnalyzer* external = nullptr,
                  const budget::AnalysisBudget& budget = budget::AnalysisBudget());

}  // namespace mbopt::worker
