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
// (kAssembly), the integrator giving up (kIntegrator), the analysis budget
// spent (kTimeLimit: its deadline or step budget; kCancelled). A driver that
// would turn more often between two instants than the step budget has steps
// is refused before anything is solved (kInvalidModel naming it): no
// analysis could follow it, and the positions would be round-off.
//
// `budget` (null: none) is checked in every loop: assembly and position
// Newton iterations, every position solve and continuation step (charged to
// its step budget), every residual of the integrators.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "spec/analysis_report.h"
#include "spec/scene.h"
#include "worker/multibody/model.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::multibody {

spec::AnalysisReport AnalyzeMultibodyScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                           budget::AnalysisBudget* budget = nullptr);

// The same analysis with the derivatives of every output with respect to
// the chosen scene parameters, whatever they set (a stiffness, a mass, a
// link length through an expression): the model is also compiled at
// p_k +- step_k (step 1e-5 |p_k|, or 1e-5 for p_k = 0) and the analysis
// differentiates through those. Forward dynamics: IDAS forward
// sensitivities (forward_dynamics.h); static equilibrium: the implicit
// function theorem at each instant (static_equilibrium.h); driven
// mechanisms: the differentiated constraint equations at each instant
// (kinematic_sensitivity.h); outputs: central differences along (state
// derivative, e_k). A bending-stress output is differenced the same way at
// every node: the perturbed models carry the parameter's effect on the
// section (modulus, area, hence stiffness and fibre distance).
struct MultibodySensitivityResult {
  spec::AnalysisReport report;
  // [k][output][series][instant]: d output / d parameter_values_si[parameters[k]],
  // as many series per output as its values (a stress output: one per node);
  // empty when `unavailable` says why (the values in `report` still count).
  std::vector<std::vector<std::vector<std::vector<double>>>> output_derivatives;
  std::string unavailable;
};
MultibodySensitivityResult AnalyzeMultibodySceneWithSensitivities(const spec::Scene& scene,
                                                                  const std::vector<double>& parameter_values_si,
                                                                  const std::vector<int>& parameters,
                                                                  budget::AnalysisBudget* budget = nullptr);

// Empty if the scene's analysis has simulator sensitivities; else why not
// (not a multibody scene).
std::string MultibodySensitivityUnavailable(const spec::Scene& scene);

// The model of a multibody scene at the given parameter values (SI), checked
// (Model::Validate). `scene.model` must hold a MultibodyModel.
absl::StatusOr<Model> CompileModel(const spec::Scene& scene, const std::vector<double>& parameter_values_si);

}  // namespace mbopt::multibody
