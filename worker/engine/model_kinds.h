// The table of scene model kinds: the one place in the engine that knows
// which kinds there are. Each entry says how a scene of its kind is
// analysed, whether the analysis has simulator sensitivities (and why not),
// and what the report's counters count for it. Analyses and gradients are
// dispatched through the entry of the scene's kind (ModelKindOf); nothing
// else branches on the kind.
#pragma once

#include <string>
#include <vector>

#include "spec/analysis_report.h"
#include "spec/scene.h"
#include "worker/engine/external_analyzer.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::engine {

// An analysis with the derivatives of its outputs with respect to chosen
// scene parameters.
struct SensitivityAnalysis {
  spec::AnalysisReport report;
  // [k][output][series][instant]: d output / d parameter_values_si[parameters[k]],
  // one derivative series per series of the output's values (a flexible
  // link's stress: one per node); empty when `unavailable` says why (the
  // values in `report` still count).
  std::vector<std::vector<std::vector<std::vector<double>>>> output_derivatives;
  std::string unavailable;
};

// Engines whose outputs all have one series give [k][output][instant]: the
// same derivatives, each output's series wrapped as its only one.
std::vector<std::vector<std::vector<std::vector<double>>>> OneSeriesPerOutput(
    std::vector<std::vector<std::vector<double>>> derivatives);

struct ModelKind {
  const char* name;  // the scene file's name of the kind
  // How the kind is analysed, in one line (docs/architecture.md shows it).
  const char* analysis;
  // What the counters of its reports count.
  const char* counters;

  // One analysis of `scene` at one SI value per scene parameter, within
  // `budget` (the scene's own limits already applied; never null).
  // `external` runs external scenes (null: they fail).
  spec::AnalysisReport (*analyze)(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                  budget::AnalysisBudget* budget, const ExternalAnalyzer* external);

  // "" when an analysis of `scene` has simulator sensitivities with respect
  // to the scene parameters `parameters`; else why not (the caller then
  // differences plain analyses).
  std::string (*sensitivities_unavailable)(const spec::Scene& scene, const std::vector<int>& parameters);

  // The analysis with sensitivities; only called when
  // sensitivities_unavailable said "". Null for kinds that never have them.
  // `external` as for `analyze`.
  SensitivityAnalysis (*analyze_with_sensitivities)(const spec::Scene& scene,
                                                    const std::vector<double>& parameter_values_si,
                                                    const std::vector<int>& parameters,
                                                    budget::AnalysisBudget* budget,
                                                    const ExternalAnalyzer* external);
};

// The entry of `scene`'s model kind.
const ModelKind& ModelKindOf(const spec::Scene& scene);

// Every entry, in the order of spec::Scene::model's alternatives.
const std::vector<ModelKind>& ModelKinds();

}  // namespace mbopt::engine
