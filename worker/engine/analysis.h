// The analysis engine's entry point: one simulation of a scene at one set of
// parameter values. Pure: no gRPC, no SQLite, no threads. The engine picks the
// cheapest formulation the scene allows and computes only the requested
// outputs. Failure is data: a failed analysis carries its kind and a reason
// (spec/analysis_outcome.h), never a crash and never a silent wrong value.
#pragma once

#include <vector>

#include "spec/analysis_report.h"
#include "spec/scene.h"

namespace mbopt::engine {

// Runs one analysis. `parameter_values_si` has one SI value per scene
// parameter. The report's counters include the wall time.
spec::AnalysisReport Analyze(const spec::Scene& scene, const std::vector<double>& parameter_values_si);

}  // namespace mbopt::engine
