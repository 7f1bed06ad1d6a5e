// Analysis of a multibody scene (spec::MultibodyModel) at one design point:
// compiles the scene with the design's parameter values into a Model,
// assembles it at t = 0, and picks the analysis from the degrees of freedom
// left once driven: none, a kinematic analysis (no time integration; with
// inverse dynamics only when an output needs joint reactions or driver
// efforts); one or more, forward dynamics with IDAS. Computes only the
// requested outputs, at the scene's grid instants.
//
// Failures are data with their kind: unusable parameter values or redundant
// joints (kInvalidModel), a mechanism that cannot assemble or locks
// (kAssembly), the integrator giving up (kIntegrator), the wall-time limit.
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "spec/analysis_report.h"
#include "spec/scene.h"
#include "worker/multibody/model.h"

namespace mbopt::multibody {

spec::AnalysisReport AnalyzeMultibodyScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si);

// The model of a multibody scene at the given parameter values (SI), checked
// (Model::Validate). `scene.model` must hold a MultibodyModel.
absl::StatusOr<Model> CompileModel(const spec::Scene& scene, const std::vector<double>& parameter_values_si);

}  // namespace mbopt::multibody
