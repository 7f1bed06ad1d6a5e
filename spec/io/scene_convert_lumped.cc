// A `lumped` model: bodies, ground inputs and spring-damper elements.
#include "spec/io/scene_converter.h"

#include <map>
#include <optional>
#include <set>
#include <string>

#include "absl/strings/str_cat.h"
#include "spec/io/declared_name.h"

namespace mbopt::spec::io {

LumpedModel SceneConverter::ConvertLumped(const v1::LumpedModel& m, const Where& w) {
  LumpedModel out;
  std::map<std::string, int> bodies, inputs;
  for (int i = 0; i < m.bodies_size(); ++i) {
    const v1::Body& b = m.bodies(i);
    const Where bw = w.Child("bodies", i);
    Body body;
    body.name = b.name();
    CheckDeclaredName(bw, b.name(), bodies.emplace(b.name(), i).second,
                      {.missing = "a body needs a name", .duplicate = "body name"}, &errors_);
    std::set<int> dofs;
    for (int d = 0; d < b.dofs_size(); ++d) {
      if (!dofs.insert(b.dofs(d)).second) {
        errors_.Add(bw, "dofs", d, "duplicate degree of freedom");
        continue;
      }
      switch (b.dofs(d)) {
        case v1::DOF_X:
          body.dofs.push_back(Dof::kX);
          break;
        case v1::DOF_Y:
          body.dofs.push_back(Dof::kY);
          break;
        case v1::DOF_ROTATION:
          body.dofs.push_back(Dof::kRotation);
          break;
        default:
          errors_.Add(bw, "dofs", d, "expected DOF_X, DOF_Y or DOF_ROTATION");
      }
    }
    const bool translates = dofs.count(v1::DOF_X) > 0 || dofs.count(v1::DOF_Y) > 0;
    const bool rotates = dofs.count(v1::DOF_ROTATION) > 0;
    body.mass_kg = Num(bw, "mass_kg", b.has_mass_kg(), b.mass_kg(), Dimension::kMass,
                       translates ? std::nullopt : std::optional<double>(0.0));
    if (translates) RequirePositive(bw, "mass_kg", body.mass_kg);
    body.inertia_kg_m2 =
        Num(bw, "inertia_kg_m2", b.has_inertia_kg_m2(), b.inertia_kg_m2(), Dimension::kInertia,
            rotates ? std::nullopt : std::optional<double>(0.0));
    if (rotates) RequirePositive(bw, "inertia_kg_m2", body.inertia_kg_m2);
    body.position_m =
        Vec(bw, "position_m", b.has_position_m(), b.position_m(), Dimension::kLength);
    out.bodies.push_back(std::move(body));
  }
  if (m.bodies_size() == 0) errors_.Add(w, "bodies", "a lumped model needs at least one body");
  for (int i = 0; i < m.inputs_size(); ++i) {
    const v1::GroundInput& g = m.inputs(i);
    const Where iw = w.Child("inputs", i);
    GroundInput input;
    input.name = g.name();
    CheckDeclaredName(iw, g.name(), inputs.emplace(g.name(), i).second,
                      {.missing = "an input needs a name", .duplicate = "input name"}, &errors_);
    if (g.profile_case() != v1::GroundInput::kCosineBump) {
      errors_.Add(iw, "", "missing profile: expected `cosine_bump { ... }`");
    } else {
      const Where cw = iw.Child("cosine_bump");
      const v1::CosineBump& c = g.cosine_bump();
      input.bump.height_m =
          Num(cw, "height_m", c.has_height_m(), c.height_m(), Dimension::kLength);
      input.bump.length_m =
          Num(cw, "length_m", c.has_length_m(), c.length_m(), Dimension::kLength);
      RequirePositive(cw, "length_m", input.bump.length_m);
      input.bump.speed_m_per_s = Num(cw, "speed_m_per_s", c.has_speed_m_per_s(),
                                     c.speed_m_per_s(), Dimension::kVelocity);
      RequirePositive(cw, "speed_m_per_s", input.bump.speed_m_per_s);
      input.bump.start_time_s =
          Num(cw, "start_time_s", c.has_start_time_s(), c.start_time_s(), Dimension::kTime, 0.0);
    }
    input.delay_s = Num(iw, "delay_s", g.has_delay_s(), g.delay_s(), Dimension::kTime, 0.0);
    Direction(iw, "direction", g.has_direction(), g.direction(), &input.direction_x,
              &input.direction_y);
    out.inputs.push_back(std::move(input));
  }
  std::set<std::string> element_names;
  for (int i = 0; i < m.elements_size(); ++i) {
    const v1::SpringDamper& e = m.elements(i);
    const Where ew = w.Child("elements", i);
    SpringDamper element;
    element.name = e.name();
    CheckDeclaredName(ew, e.name(), element_names.insert(e.name()).second,
                      {.missing = "an element needs a name", .duplicate = "element name"}, &errors_);
    element.a = Attach(ew, "a", e.has_a(), e.a(), bodies, inputs);
    element.b = Attach(ew, "b", e.has_b(), e.b(), bodies, inputs);
    Direction(ew, "direction", e.has_direction(), e.direction(), &element.direction_x,
              &element.direction_y);
    element.stiffness_n_per_m = Num(ew, "stiffness_n_per_m", e.has_stiffness_n_per_m(),
                                    e.stiffness_n_per_m(), Dimension::kStiffness, 0.0);
    RequireNotNegative(ew, "stiffness_n_per_m", element.stiffness_n_per_m);
    element.damping_n_s_per_m = Num(ew, "damping_n_s_per_m", e.has_damping_n_s_per_m(),
                                    e.damping_n_s_per_m(), Dimension::kDamping, 0.0);
    RequireNotNegative(ew, "damping_n_s_per_m", element.damping_n_s_per_m);
    out.elements.push_back(std::move(element));
  }
  lumped_bodies_ = bodies;
  lumped_elements_.clear();
  for (size_t i = 0; i < out.elements.size(); ++i) {
    lumped_elements_.emplace(out.elements[i].name, static_cast<int>(i));
  }
  return out;
}

Attachment SceneConverter::Attach(const Where& w, const std::string& field, bool present, const v1::Attachment& a,
                  const std::map<std::string, int>& bodies,
                  const std::map<std::string, int>& inputs) {
  Attachment out;
  if (!present) {
    errors_.Add(w, field,
                "missing: expected `{ body: \"name\" }`, `{ input: \"name\" }` or "
                "`{ ground: true }`");
    return out;
  }
  const Where aw = w.Child(field);
  switch (a.target_case()) {
    case v1::Attachment::kBody: {
      out.kind = Attachment::Kind::kBody;
      auto it = bodies.find(a.body());
      if (it == bodies.end()) {
        errors_.Add(aw, "body", absl::StrCat("unknown body \"", a.body(), "\""));
      } else {
        out.index = it->second;
      }
      out.offset_m = Vec(aw, "offset_m", a.has_offset_m(), a.offset_m(), Dimension::kLength);
      break;
    }
    case v1::Attachment::kInput: {
      out.kind = Attachment::Kind::kInput;
      auto it = inputs.find(a.input());
      if (it == inputs.end()) {
        errors_.Add(aw, "input", absl::StrCat("unknown input \"", a.input(), "\""));
      } else {
        out.index = it->second;
      }
      break;
    }
    case v1::Attachment::kGround:
      out.kind = Attachment::Kind::kGround;
      break;
    case v1::Attachment::TARGET_NOT_SET:
      errors_.Add(w, field, "expected `body: \"name\"`, `input: \"name\"` or `ground: true`");
      break;
  }
  if (a.has_offset_m() && out.kind != Attachment::Kind::kBody) {
    errors_.Add(aw, "offset_m", "an offset is only meaningful on a body attachment");
  }
  return out;
}

}  // namespace mbopt::spec::io
