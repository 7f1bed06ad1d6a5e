// One analysis of a study at one scaled design point, in this process:
// scaled x -> SI parameter values (Study::ParameterValuesAt) -> engine::Analyze
// -> the study's values (objective terms, constraint rows) of the layout.
//
// What it is for: the evaluator of RunStudyLocally, and tools that re-check a
// design, e.g. on a finer time grid (evaluate with a study whose scene has a
// different grid and the layout made from that study).
//
// Pure: no threads, no I/O. A failed analysis and a non-finite study value
// are data (DesignEvaluation::ok() false, with a reason), not an error
// status; only inputs that cannot belong together (x of the wrong size, a
// report whose outputs do not have the layout's shape) are InvalidArgument.
#pragma once

#include <optional>
#include <string>

#include <Eigen/Dense>

#include "absl/status/statusor.h"
#include "server/slp/slp_optimizer.h"
#include "spec/layout.h"
#include "spec/study.h"
#include "spec/study_gradients.h"
#include "worker/engine/analysis.h"

namespace mbopt::local_run {

struct DesignEvaluation {
  // The engine report's status and reason; kFailed also when the analysis
  // succeeded but a study value is NaN or infinite (the reason names it).
  engine::AnalysisStatus status = engine::AnalysisStatus::kOk;
  std::string failure_reason;
  engine::Formulation formulation = engine::Formulation::kKinematic;
  engine::AnalysisCounters counters;  // of this analysis, wall time included
  // Present exactly when status is kOk: every value in it is finite.
  std::optional<spec::StudyValues> values;
  // EvaluateDesignWithGradients only: the values' gradients with respect to
  // the scaled variables (absent when unavailable or not finite: why, in
  // gradients_unavailable).
  std::optional<spec::StudyGradients> gradients;
  std::string gradients_unavailable;

  bool ok() const { return status == engine::AnalysisStatus::kOk; }
};

// `x_scaled` has one entry per study variable (spec::DesignVariable::scale
// maps it to the parameter's unit). `layout` must be MakeStudyLayout(study).
absl::StatusOr<DesignEvaluation> EvaluateDesign(const spec::Study& study,
                                                const spec::StudyLayout& layout,
                                                const Eigen::VectorXd& x_scaled);

// As EvaluateDesign, from one analysis that also carries the simulator's
// sensitivities (engine::AnalyzeStudyWithGradients).
absl::StatusOr<DesignEvaluation> EvaluateDesignWithGradients(const spec::Study& study,
                                                             const spec::StudyLayout& layout,
                                                             const Eigen::VectorXd& x_scaled);

// The optimizer's view of an evaluation: kOk with the terms and the constraint
// values (and their gradients when present), or kFailed with the reason.
// request_id is left 0.
slp::AnalysisResult ToAnalysisResult(const DesignEvaluation& evaluation);

}  // namespace mbopt::local_run
