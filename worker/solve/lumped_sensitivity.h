// Forward sensitivity analysis of a lumped scene (CVODES): one integration of
// M q'' + C q' + K q = f(t) together with the sensitivity equations
//
//     M s'' + C s' + K s = df/dp - (dM/dp) q'' - (dC/dp) q' - (dK/dp) q,
//
// s = dq/dp, for each chosen scene parameter p. The system is linear, so
// these are the exact derivatives of the equations of motion; CVODES
// integrates them with the staggered corrector and includes them in its
// error test. Outputs and their derivatives are reported at the grid
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
#include "worker/engine/analysis.h"

namespace mbopt::solve {

// Empty if every parameter in `parameters` (scene parameter indices) enters
// the scene only where sensitivities are available; else why not.
std::string LumpedSensitivityUnavailable(const spec::Scene& scene,
                                         const std::vector<int>& parameters);

struct LumpedSensitivityResult {
  // Values as SimulateLumped reports them (kDynamic, grid, one series per
  // output), from the integration that also carried the sensitivities.
  engine::AnalysisReport report;
  // [k][output][instant]: d output / d parameter_values_si[parameters[k]],
  // SI per SI. Filled when report.status is kOk.
  std::vector<std::vector<std::vector<double>>> output_derivatives;
};

// `scene.model` must hold a LumpedModel and LumpedSensitivityUnavailable
// must be empty (else the report fails with that reason).
LumpedSensitivityResult SimulateLumpedWithSensitivities(
    const spec::Scene& scene, const std::vector<double>& parameter_values_si,
    const std::vector<int>& parameters);

}  // namespace mbopt::solve
