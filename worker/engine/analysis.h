// The analysis engine's entry point: one simulation of a scene at one set of
// parameter values. Pure: no gRPC, no SQLite, no threads, and no clock: the
// caller's budget brings one (worker/budget/analysis_budget.h). The engine
// picks the cheapest formulation the scene allows (through the table of
// model kinds, model_kinds.h) and computes only the requested outputs.
// Failure is data: a failed analysis carries its kind and a reason
// (spec/analysis_outcome.h), never a crash and never a silent wrong value.
#pragma once

#include <vector>

#include "spec/analysis_report.h"
#include "spec/scene.h"
#include "spec/study.h"
#include "worker/engine/external_analyzer.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::engine {

// Runs one analysis. `parameter_values_si` has one SI value per scene
// parameter. `external` runs an external scene (external_analyzer.h); none:
// such a scene fails. `budget` is the caller's clock and cancel flag; the
// analysis runs within it and within the scene's integrator.max_wall_seconds
// and max_steps, and its report's wall time is read on the budget's clock
// (0 without one).
spec::AnalysisReport Analyze(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                             const ExternalAnalyzer* external = nullptr,
                             const budget::AnalysisBudget& budget = budget::AnalysisBudget());

// Every load case of `study` (Study::cases; the scene as it is when there
// are none) at the design's SI parameter values: one report whose outputs
// are the cases' outputs in signal order, named as Study::SignalName names
// them, with the counters (wall time included) summed over the cases. The
// first case that fails fails the report, its reason naming the case. Each
// case is one analysis within `budget`, as Analyze.
spec::AnalysisReport AnalyzeCases(const spec::Study& study, const std::vector<double>& parameter_values_si,
                                  const ExternalAnalyzer* external = nullptr,
                                  const budget::AnalysisBudget& budget = budget::AnalysisBudget());

// Adds load case `c`'s report to `combined` as AnalyzeCases does; false (and
// `combined` failed) when the case failed.
bool AppendCaseReport(const spec::Study& study, int c, spec::AnalysisReport report, spec::AnalysisReport* combined);

}  // namespace mbopt::engine
