// The drawing of a scene at one design point, by model kind: multibody,
// linkage and spatial scenes over their time grid, lumped scenes as a
// schematic. What `mbopt-worker draw` writes; never part of an analysis (a
// scene computes only the outputs asked for, and a drawing is not one).
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "spec/scene.h"
#include "spec/scene_drawing.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::engine {

// InvalidArgument for a scene kind that has no drawing (external, FMU) or a
// parameter vector of another size. A motion that cannot be followed is no
// error: the drawing holds the instants before and says why
// (SceneDrawing::failure).
absl::StatusOr<spec::SceneDrawing> DrawScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                             budget::AnalysisBudget* budget = nullptr);

}  // namespace mbopt::engine
