// What a worker does with one task: the scaled design point becomes scene
// parameter values, the engine analyses the scene there, and the study layout
// turns its outputs into the study values the optimizer asked for (objective
// terms and constraint values g_h, aligned with spec::MakeStudyLayout). Every
// way this can go wrong (the engine fails, a shape does not match, a value is
// NaN or infinite) becomes a result with ok = false and a reason: the
// optimizer decides what a failed analysis means.
#pragma once

#include <memory>

#include "absl/status/statusor.h"
#include "mbopt/v1/service.pb.h"
#include "spec/layout.h"
#include "spec/study.h"

namespace mbopt::worker {

// A job's study, converted once and shared by every task of the job.
struct PreparedStudy {
  spec::Study study;
  spec::StudyLayout layout;
};

// InvalidArgument if the study (as the server sent it) does not convert.
absl::StatusOr<std::shared_ptr<const PreparedStudy>> PrepareStudy(const v1::Study& study,
                                                                  const std::string& job_id);

// Fills everything of `result` except worker_id, task_id, job_id and
// request_id.
void EvaluateTask(const PreparedStudy& prepared, const v1::AnalysisTask& task,
                  v1::TaskResult* result);

}  // namespace mbopt::worker
