// One analysis of an `fmu` scene (spec::FmuModel): the FMU opened, its
// parameters set from the scene's Numbers at the design's parameter values,
// simulated from t = 0 and its variables reported on the scene's time grid,
// as the engine's other formulations report theirs.
//
// Each analysis opens the FMU afresh (its own unpacked copy and instance),
// so analyses share no state and give the same values in any order.
// Failures are data: an archive or name the FMU does not have is
// kInvalidModel naming it; the FMU's errors kInvalidModel, the integrator
// giving up kIntegrator, the FMU ending the run early kModelValidity, the
// wall-time limit kTimeLimit, a NaN kNonFiniteValue.
#pragma once

#include <string>
#include <vector>

#include "spec/analysis_report.h"
#include "spec/scene.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::fmu {

// `budget` (null: none) is checked after every integrator step and every
// fmi2DoStep.
spec::AnalysisReport AnalyzeFmuScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                     const budget::AnalysisBudget* budget = nullptr);

// Simulator sensitivities of an `fmu` scene (sensitivities.h): with respect
// to scene parameters, through the FMU parameters they set (a scene
// parameter may set several, through expressions; the chain rule sums them).
//
// "" when the scene's FMU gives sensitivities with respect to `parameters`
// (scene parameter indices); else why not (the FMU is opened to read its
// description: a few milliseconds).
std::string FmuSensitivitiesUnavailable(const spec::Scene& scene, const std::vector<int>& parameters);

struct FmuSensitivityAnalysis {
  spec::AnalysisReport report;
  // [k][output][instant]: d output / d parameter_values_si[parameters[k]];
  // empty when `unavailable` says why.
  std::vector<std::vector<std::vector<double>>> output_derivatives;
  std::string unavailable;
};

FmuSensitivityAnalysis AnalyzeFmuSceneWithSensitivities(const spec::Scene& scene,
                                                        const std::vector<double>& parameter_values_si,
                                                        const std::vector<int>& parameters,
                                                        const budget::AnalysisBudget* budget = nullptr);

}  // namespace mbopt::fmu
