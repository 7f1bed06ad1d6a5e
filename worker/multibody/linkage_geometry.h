// The drawing of a linkage scene (spec::LinkageModel) over its time grid:
// each link as a bar between its pins with its points, the pins, the ground
// pins hatched. The motion is the rigid linkage's kinematics on the
// multibody engine, as the linkage analysis solves it (the driver turning
// at most 10 degrees between two solved instants, so the assembly branch is
// followed); the elastic deflection of flexible links is not drawn.
// Computed only when asked: AnalyzeLinkageScene does no work for it. Pure.
#pragma once

#include <vector>

#include "spec/scene.h"
#include "spec/scene_drawing.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::multibody {

spec::SceneDrawing DrawLinkageScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                    budget::AnalysisBudget* budget = nullptr);

}  // namespace mbopt::multibody
