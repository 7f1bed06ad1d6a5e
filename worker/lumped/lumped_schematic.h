// The schematic of a lumped scene (spec::LumpedModel): its bodies as boxes,
// its spring-dampers between them or to the ground, and its ground inputs,
// from the scene alone (no analysis: a lumped scene's motion is small about
// a layout that is not a mechanism's geometry). Bodies stand at their
// declared x; an element along y puts its end a above its end b, so each
// body gets a level above the ground and the inputs. One instant, t = 0.
// Pure: no I/O.
#pragma once

#include <vector>

#include "spec/scene.h"
#include "spec/scene_drawing.h"

namespace mbopt::lumped {

spec::SceneDrawing LumpedSchematic(const spec::Scene& scene, const std::vector<double>& parameter_values_si);

}  // namespace mbopt::lumped
