#include "worker/engine/scene_drawing.h"

#include <string>
#include <variant>

#include "absl/strings/str_format.h"
#include "worker/lumped/lumped_schematic.h"
#include "worker/multibody/linkage_geometry.h"
#include "worker/multibody/scene_geometry.h"
#include "worker/spatial/spatial_drawing.h"

namespace mbopt::engine {

absl::StatusOr<spec::SceneDrawing> DrawScene(const spec::Scene& scene, const std::vector<double>& p,
                                             budget::AnalysisBudget* budget) {
  if (p.size() != scene.parameters.size()) {
    return absl::InvalidArgumentError(absl::StrFormat("scene '%s' has %d parameters, %d values given", scene.name,
                                                      scene.parameters.size(), p.size()));
  }
  if (std::holds_alternative<spec::MultibodyModel>(scene.model)) return multibody::DrawMultibodyScene(scene, p, budget);
  if (std::holds_alternative<spec::LinkageModel>(scene.model)) return multibody::DrawLinkageScene(scene, p, budget);
  if (std::holds_alternative<spec::SpatialModel>(scene.model)) return spatial::DrawSpatialScene(scene, p, budget);
  if (std::holds_alternative<spec::LumpedModel>(scene.model)) return lumped::LumpedSchematic(scene, p);
  return absl::InvalidArgumentError(absl::StrFormat(
      "scene '%s' (%s): only multibody, linkage and lumped scenes can be drawn, and spatial ones; an "
      "external or FMU scene's geometry is not known to mbopt",
      scene.name, scene.source_file));
}

}  // namespace mbopt::engine
