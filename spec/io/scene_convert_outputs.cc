// The scene's outputs, each checked against what its model kind can produce.
#include "spec/io/scene_converter.h"

#include <map>
#include <set>
#include <string>
#include <variant>

#include "absl/strings/str_cat.h"
#include "spec/io/declared_name.h"

namespace mbopt::spec::io {

void SceneConverter::ConvertOutputs() {
  std::set<std::string> names;
  const bool lumped = std::holds_alternative<LumpedModel>(scene_.model);
  const bool linkage = std::holds_alternative<LinkageModel>(scene_.model);
  const bool multibody = std::holds_alternative<MultibodyModel>(scene_.model);
  const bool external = std::holds_alternative<ExternalModel>(scene_.model);
  const bool spatial = std::holds_alternative<SpatialModel>(scene_.model);
  auto lookup = [&](const std::map<std::string, int>& table, const Where& w,
                    const std::string& field, const std::string& name, const char* what) {
    auto it = table.find(name);
    if (it == table.end()) {
      errors_.Add(w, field, absl::StrCat("unknown ", what, " \"", name, "\""));
      return -1;
    }
    return it->second;
  };
  auto axis = [&](const Where& w, v1::Axis a) {
    if (a == v1::AXIS_X) return Axis::kX;
    if (a != v1::AXIS_Y) errors_.Add(w, "axis", "expected AXIS_X or AXIS_Y");
    return Axis::kY;
  };
  for (int i = 0; i < msg_.outputs_size(); ++i) {
    const v1::Output& o = msg_.outputs(i);
    const Where ow = where_.Child("outputs", i);
    Output out;
    out.name = o.name();
    CheckDeclaredName(ow, o.name(), names.insert(o.name()).second,
                      {.missing = "an output needs a name", .duplicate = "output name"}, &errors_);
    const char* needs = nullptr;  // the model kind this output needs
    switch (o.kind_case()) {
      case v1::Output::kElementDeflection: {
        needs = "lumped";
        ElementDeflectionOutput k;
        if (lumped) {
          k.element = lookup(lumped_elements_, ow.Child("element_deflection"), "element",
                             o.element_deflection().element(), "element");
        }
        out.kind = k;
        break;
      }
      case v1::Output::kBodyAcceleration:
      case v1::Output::kBodyDisplacement:
      case v1::Output::kBodyVelocity: {
        needs = "lumped";
        using Q = BodyAccelerationOutput::Quantity;
        const bool displacement = o.kind_case() == v1::Output::kBodyDisplacement;
        const bool velocity = o.kind_case() == v1::Output::kBodyVelocity;
        const Where kw =
            ow.Child(displacement ? "body_displacement" : velocity ? "body_velocity" : "body_acceleration");
        const v1::BodyAccelerationOutput& a =
            displacement ? o.body_displacement() : velocity ? o.body_velocity() : o.body_acceleration();
        BodyAccelerationOutput k;
        k.quantity = displacement ? Q::kDisplacement : velocity ? Q::kVelocity : Q::kAcceleration;
        if (lumped) k.body = lookup(lumped_bodies_, kw, "body", a.body(), "body");
        k.offset_m = Vec(kw, "offset_m", a.has_offset_m(), a.offset_m(), Dimension::kLength);
        k.axis = axis(kw, a.axis());
        out.kind = k;
        break;
      }
      case v1::Output::kPointPosition: {
        needs = "linkage";
        const Where kw = ow.Child("point_position");
        PointPositionOutput k;
        k.axis = axis(kw, o.point_position().axis());
        if (linkage) ResolvePoint(kw, o.point_position().point(), &k);
        out.kind = k;
        break;
      }
      case v1::Output::kLinkRotation: {
        needs = "linkage";
        LinkRotationOutput k;
        if (linkage) {
          k.link = lookup(linkage_links_, ow.Child("link_rotation"), "link",
                          o.link_rotation().link(), "link");
        }
        out.kind = k;
        break;
      }
      case v1::Output::kBendingStress: {
        needs = multibody ? "multibody" : "linkage";
        BendingStressOutput k;
        const Where kw = ow.Child("bending_stress");
        if (multibody) {
          k.link = lookup(multibody_links_, kw, "link", o.bending_stress().link(), "flexible link");
        }
        if (linkage) {
          k.link = lookup(linkage_links_, kw, "link", o.bending_stress().link(), "link");
          const auto& linkage = std::get<LinkageModel>(scene_.model);
          if (k.link >= 0 && !linkage.links[static_cast<size_t>(k.link)].section) {
            errors_.Add(kw, "link",
                        absl::StrCat("link \"", o.bending_stress().link(),
                                     "\" has no section: bending stress needs one"));
          }
        }
        out.kind = k;
        break;
      }
      case v1::Output::kDriveTorque:
        needs = "linkage";
        out.kind = DriveTorqueOutput{};
        break;
      case v1::Output::kMass:
        needs = "linkage";
        out.kind = MassOutput{};
        break;
      case v1::Output::kDriverEffort:
      case v1::Output::kJointReaction:
      case v1::Output::kMarkerPosition:
      case v1::Output::kMarkerVelocity:
      case v1::Output::kMarkerAcceleration:
      case v1::Output::kJointCoordinate:
      case v1::Output::kJointRate:
      case v1::Output::kSpringLength:
      case v1::Output::kSpringForce:
      case v1::Output::kKineticEnergy:
      case v1::Output::kPotentialEnergy:
        if (spatial) {
          needs = "spatial";
          out.kind = SpatialOutputOf(o, ow);
          break;
        }
        needs = "multibody";
        out.kind = multibody ? MultibodyOutputOf(o, ow) : MultibodyOutput{};
        break;
      case v1::Output::kBodyOrientation:
      case v1::Output::kJointSlide:
      case v1::Output::kJointSlideRate:
      case v1::Output::kBodyAngularVelocity:
      case v1::Output::kJointReactionMoment:
      case v1::Output::kBushingForce:
      case v1::Output::kRotationalSpringTorque:
        needs = "spatial";
        out.kind = spatial ? SpatialOutputOf(o, ow) : SpatialOutput{};
        break;
      case v1::Output::kExternalValue:
      case v1::Output::kExternalSeries: {
        needs = "external";
        const bool series = o.kind_case() == v1::Output::kExternalSeries;
        const v1::ExternalResultOutput& r = series ? o.external_series() : o.external_value();
        if (r.name().empty()) {
          errors_.Add(ow.Child(series ? "external_series" : "external_value"), "name",
                      "missing: expected the name the driver writes in its results file");
        }
        out.kind = ExternalResultOutput{r.name(), series};
        break;
      }
      case v1::Output::kFmuVariable:
        needs = "fmu";
        if (o.fmu_variable().variable().empty()) {
          errors_.Add(ow.Child("fmu_variable"), "variable", "missing: expected the FMU variable's name");
        }
        out.kind = FmuVariableOutput{o.fmu_variable().variable()};
        break;
      case v1::Output::KIND_NOT_SET:
        errors_.Add(ow, "", "the output has no kind (e.g. `element_deflection { ... }`)");
        break;
    }
    const char* model_kind = lumped      ? "lumped"
                             : linkage   ? "linkage"
                             : multibody ? "multibody"
                             : external  ? "external"
                             : spatial   ? "spatial"
                                         : "fmu";
    if (needs != nullptr && std::string(needs) != model_kind) {
      errors_.Add(ow, "",
                  absl::StrCat("output \"", o.name(), "\" needs ", needs[0] == 'e' ? "an " : "a ", needs,
                               " model; this scene's model is ",
                               model_kind));
    }
    scene_.outputs.push_back(std::move(out));
  }
}

void SceneConverter::ResolvePoint(const Where& w, const std::string& name, PointPositionOutput* k) {
  const auto& linkage = std::get<LinkageModel>(scene_.model);
  const size_t dot = name.find('.');
  if (dot == std::string::npos) {
    auto it = linkage_joints_.find(name);
    if (it == linkage_joints_.end()) {
      errors_.Add(
          w, "point",
          absl::StrCat("unknown joint \"", name, "\" (a link point is written \"link.point\")"));
    } else {
      k->joint = it->second;
    }
    return;
  }
  const std::string link_name = name.substr(0, dot), point_name = name.substr(dot + 1);
  auto it = linkage_links_.find(link_name);
  if (it == linkage_links_.end()) {
    errors_.Add(w, "point", absl::StrCat("unknown link \"", link_name, "\""));
    return;
  }
  k->link = it->second;
  const Link& link = linkage.links[static_cast<size_t>(k->link)];
  for (size_t p = 0; p < link.points.size(); ++p) {
    if (link.points[p].name == point_name) k->point = static_cast<int>(p);
  }
  if (k->point < 0) {
    errors_.Add(w, "point",
                absl::StrCat("link \"", link_name, "\" has no point \"", point_name, "\""));
  }
}

}  // namespace mbopt::spec::io
