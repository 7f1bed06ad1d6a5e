// Analysis of a spatial scene (spec::SpatialModel) at one design point:
// compiles the scene with the design's parameter values into a Model,
// assembles it at t = 0 (AssembleSpatial) and, when every degree of
// freedom is driven, runs its kinematic analysis (RunSpatialKinematics);
// otherwise it integrates its forward dynamics with IDAS
// (multibody::IntegrateForward, the planar kernel's GGL integrator) to
// every grid instant. A scene asking for static equilibrium
// (spatial_static_equilibrium.h) gets it at every grid instant instead,
// reactions and efforts from its multipliers. Computes only the requested
// outputs, at the scene's grid instants (driver efforts by inverse dynamics
// from each state of a motion).
//
// Failures are data with their kind: unusable parameter values or
// redundant joints (kInvalidModel, naming the body or joint), a mechanism
// that cannot assemble (kAssembly), the integrator giving up (kIntegrator),
// the analysis budget spent (kTimeLimit, kCancelled).
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "spec/analysis_report.h"
#include "spec/scene.h"
#include "worker/budget/analysis_budget.h"
#include "worker/spatial/spatial_model.h"

namespace mbopt::spatial {

spec::AnalysisReport AnalyzeSpatialScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                         budget::AnalysisBudget* budget = nullptr);

// The model of a spatial scene at the given parameter values (SI), checked
// (Model::Validate). `scene.model` must hold a SpatialModel.
absl::StatusOr<Model> CompileSpatialModel(const spec::Scene& scene, const std::vector<double>& parameter_values_si);

}  // namespace mbopt::spatial
