// The analysis engine's entry point: one simulation of a scene at one set of
// parameter values. Pure: no gRPC, no SQLite, no threads. The engine picks the
// cheapest formulation the scene allows and computes only the requested
// outputs. Failure is data: a failed analysis carries its kind and a reason
// (spec/analysis_outcome.h), never a crash and never a silent wrong value.
#pragma once

#include <vector>

#include "spec/analysis_report.h"
#include "spec/scene.h"
#include "spec/study.h"
#include "worker/engine/external_analyzer.h"

namespace mbopt::engine {

// Runs one analysis. `parameter_values_si` has one SI value per scene
// parameter. The report's counters include the wall time. `external` runs an
// external scene (external_analyzer.h); none: such a scene fails.
spec::AnalysisReport Analyze(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                             const ExternalAnalyzer* external = nullptr);

// Every load case of `study` (Study::cases; the scene as it is when there
// are none) at the design's SI parameter values: one report whose outputs
// are the cases' outputs in signal order, named as Study::SignalName names
// them, with the counters (wall time included) summed over the cases. The
// first case that fails fails the report, its reason naming the case.
spec::AnalysisReport AnalyzeCases(const spec::Study& study, const std::vector<double>& parameter_values_si,
                                  const ExternalAnalyzer* external = nullptr);

// Adds load case `c`'s report to `combined` as AnalyzeCases does; false (and
// `combined` failed) when the case failed.
bool AppendCaseReport(const spec::Study& study, int c, spec::AnalysisReport report, spec::AnalysisReport* combined);

}  // namespace mbopt::engine
