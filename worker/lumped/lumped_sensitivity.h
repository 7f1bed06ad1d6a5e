// Forward sensitivity analysis of a lumped scene (CVODES): one integration of
// M q'' + C q' + K q = f(t) together with the sensitivity equations
//
//     M s'' + C s' + K s = df/dp - (dM/dp) q'' - (dC/dp) q' - (dK/dp) q,
//
// s = dq/dp, for each chosen scene parameter p. The system is linear, so
// these are the exact derivatives of the equations of motion. By default
// CVODES integrates states and sensitivities as one ODE system whose Newton
// systems are solved block by block through one n x n factorization, with
// the sensitivities in the error test (at least as strictly as
// CVodeSetSensErrCon(SUNTRUE) would hold them); CVODES' forward sensitivity
// module (CVodeSensInit, analytic Jacobian and sensitivity right-hand side)
// is kept as an option. For small models the first is cheaper: measured on
// the vehicle, 5.4 plain analyses against 8.6 (bench/sensitivity,
// docs/benchmarks.md). Outputs and their derivatives are reported at the grid
// instants: an element deflection's derivative is g . s (its ground input
// does not depend on p), a body acceleration's is the point acceleration of
// dq''/dp from the differentiated equations of motion.
//
// What a parameter may set: body masses and inertias, element stiffnesses
// and dampings. A parameter that also sets an attachment offset, a bump, a
// delay or an output offset has no sensitivity here:
// LumpedSensitivityUnavailable names it and the caller uses finite
// differences instead.
//
// Failure is data as in SimulateLumped (report.status kFailed, a reason).
#pragma once

#include <string>
#include <vector>

#include "spec/scene.h"
#include "spec/analysis_report.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::lumped {

// Empty if every parameter in `parameters` (scene parameter indices) enters
// the scene only where sensitivities are available; else why not.
std::string LumpedSensitivityUnavailable(const spec::Scene& scene,
                                         const std::vector<int>& parameters);

// How CVODES corrects and controls the sensitivities. The defaults are the
// combination measured fastest on the vehicle study at unchanged accuracy
// (bench/sensitivity, docs/benchmarks.md); the alternatives are kept so that
// the benchmark can measure them.
struct LumpedSensitivityOptions {
  enum class Method {
    // States and sensitivities as one ODE system with a block Newton solve
    // (see the .cc); the sensitivities are error-controlled.
    kAugmentedSystem,
    // CVODES' forward sensitivity module (CVodeSensInit); the settings below
    // apply to this method only.
    kCvodesSensitivities,
  };
  Method method = Method::kAugmentedSystem;
  // kAugmentedSystem: tolerances divided by sqrt(1 + ns) so that its single
  // error norm bounds every block's (as strict as CVodeSetSensErrCon(SUNTRUE)).
  bool augmented_block_norm_bound = true;
  enum class Corrector {
    kSimultaneous,  // CV_SIMULTANEOUS: states and sensitivities in one Newton iteration
    kStaggered,     // CV_STAGGERED: sensitivities corrected together after the states
    kStaggered1,    // CV_STAGGERED1: each sensitivity corrected on its own
  };
  Corrector corrector = Corrector::kStaggered;
  // Sensitivities in the local error test (CVodeSetSensErrCon). Off, only
  // the states choose the step size.
  bool error_control = true;
  // 1: CVodeSensEEtolerances (the scene's rtol, atol_i / |p|). Otherwise
  // CVodeSensSVtolerances with both multiplied by this factor.
  double tolerance_factor = 1.0;
  // Steps between Jacobian evaluations and between linear-solver setups
  // (CVodeSetJacEvalFrequency, CVodeSetLSetupFrequency); 0: CVODES' default.
  long jacobian_eval_frequency = 0;
  long linear_setup_frequency = 0;
  // N_VEnableFusedOps_Serial: CVODES updates all sensitivity vectors in one
  // call per operation instead of one call per vector.
  bool fused_vector_operations = false;
  // The analysis' deadline and cancel flag, checked in every right-hand
  // side (null: none).
  const budget::AnalysisBudget* budget = nullptr;
};

// Where the integration's work went, beyond report.counters (which has the
// steps, state right-hand sides, Jacobians and state Newton iterations).
struct LumpedSensitivityCounters {
  long sensitivity_rhs_evaluations = 0;  // calls of the analytic sensitivity RHS (all k at once)
  long sensitivity_newton_iterations = 0;
  long linear_setups = 0;  // factorizations of the Newton matrix
  long error_test_failures = 0;
  long sensitivity_error_test_failures = 0;
};

struct LumpedSensitivityResult {
  // Values as SimulateLumped reports them (kDynamic, grid, one series per
  // output), from the integration that also carried the sensitivities.
  spec::AnalysisReport report;
  // [k][output][instant]: d output / d parameter_values_si[parameters[k]],
  // SI per SI. Filled when report.status is kOk.
  std::vector<std::vector<std::vector<double>>> output_derivatives;
  LumpedSensitivityCounters counters;
};

// `scene.model` must hold a LumpedModel and LumpedSensitivityUnavailable
// must be empty (else the report fails with that reason).
LumpedSensitivityResult SimulateLumpedWithSensitivities(
    const spec::Scene& scene, const std::vector<double>& parameter_values_si,
    const std::vector<int>& parameters, const LumpedSensitivityOptions& options = {});

}  // namespace mbopt::lumped
