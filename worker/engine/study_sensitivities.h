// One analysis of a study at a scaled design point that also yields the
// gradients of the study values with respect to the scaled design variables,
// from the simulator's forward sensitivity analysis of the scene's model
// kind (model_kinds.h) and the layout's chain rule (spec/study_gradients.h).
// Pure: no threads, no I/O, no clock (the budget's).
//
// Every series of an output has its derivative series (a flexible link's
// stress: one per node). When the scene has no simulator sensitivities (its
// kind has none, or a lumped design variable that sets something other than
// a mass, inertia, stiffness or damping) the plain
// analysis is run and `gradients` is empty with the reason: the caller then
// uses finite differences.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "spec/layout.h"
#include "spec/study.h"
#include "spec/study_gradients.h"
#include "worker/engine/external_analyzer.h"
#include "worker/engine/analysis.h"

namespace mbopt::engine {

struct StudyAnalysisWithGradients {
  spec::AnalysisReport report;  // wall time included
  std::optional<spec::StudyGradients> gradients;  // only when report is kOk
  std::string gradients_unavailable;              // why gradients is empty
};

// `x_scaled` has one entry per study variable; `layout` is
// MakeStudyLayout(study). An external scene is analysed by `external`, its
// gradients those its driver writes. Each load case
// is one analysis within `budget`, as engine::Analyze.
StudyAnalysisWithGradients AnalyzeStudyWithGradients(const spec::Study& study,
                                                     const spec::StudyLayout& layout,
                                                     const std::vector<double>& x_scaled,
                                                     const ExternalAnalyzer* external = nullptr,
                                                     const budget::AnalysisBudget& budget = budget::AnalysisBudget());

}  // namespace mbopt::engine
