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

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "spec/analysis_report.h"
#include "spec/scene.h"
#include "worker/budget/analysis_budget.h"
#include "worker/spatial/spatial_model.h"

namespace mbopt::spatial {

spec::AnalysisReport AnalyzeSpatialScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                         budget::AnalysisBudget* budget = nullptr);

// The same analysis with the derivatives of every output with respect to
// the chosen scene parameters, whatever they set (a mass, an inertia, a
// stiffness, a force, a marker's coordinate or orientation through an
// expression): the model is also compiled and assembled at p_k +- step_k
// (step 1e-5 |p_k|, or 1e-5 for p_k = 0). Forward dynamics: IDAS forward
// sensitivities (multibody::IntegrateForward) whose parameter terms are
// central differences of the GGL residual between the varied systems
// (there are no exact derivative models of spatial systems) and whose
// state terms come from SpatialSystem's exact state Jacobian; the unit-norm rows of the Euler parameters do not depend
// on any parameter, so their terms vanish. Driven mechanisms: the
// differentiated constraint equations at each instant
// (multibody::KinematicStateSensitivities). Outputs: central differences
// between the varied systems along (state derivative, e_k), so
// orientations follow the Euler parameters' derivatives. A mechanism with
// redundant joints has none (`unavailable` says so).
struct SpatialSensitivityResult {
  spec::AnalysisReport report;
  // [k][output][instant]: d output / d parameter_values_si[parameters[k]];
  // empty when `unavailable` says why (the values in `report` still count).
  std::vector<std::vector<std::vector<double>>> output_derivatives;
  std::string unavailable;
};
SpatialSensitivityResult AnalyzeSpatialSceneWithSensitivities(const spec::Scene& scene,
                                                              const std::vector<double>& parameter_values_si,
                                                              const std::vector<int>& parameters,
                                                              budget::AnalysisBudget* budget = nullptr);

// The model of a spatial scene at the given parameter values (SI), checked
// (Model::Validate). `scene.model` must hold a SpatialModel.
absl::StatusOr<Model> CompileSpatialModel(const spec::Scene& scene, const std::vector<double>& parameter_values_si);

}  // namespace mbopt::spatial
