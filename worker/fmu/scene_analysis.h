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

#include <vector>

#include "spec/analysis_report.h"
#include "spec/scene.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::fmu {

// `budget` (null: none) is checked after every integrator step and every
// fmi2DoStep.
spec::AnalysisReport AnalyzeFmuScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                     const budget::AnalysisBudget* budget = nullptr);

}  // namespace mbopt::fmu
