#include "spec/io/drawing_convert.h"

#include <string>
#include <vector>

#include "absl/strings/str_format.h"

namespace mbopt::spec::io {
namespace {

v1::DrawingJoint::Kind KindToProto(SceneDrawing::JointKind kind) {
  switch (kind) {
    case SceneDrawing::JointKind::kPin: return v1::DrawingJoint::KIND_PIN;
    case SceneDrawing::JointKind::kSlider: return v1::DrawingJoint::KIND_SLIDER;
    case SceneDrawing::JointKind::kFixed: return v1::DrawingJoint::KIND_FIXED;
    case SceneDrawing::JointKind::kPinInSlot: return v1::DrawingJoint::KIND_PIN_IN_SLOT;
    case SceneDrawing::JointKind::kSpherical: return v1::DrawingJoint::KIND_SPHERICAL;
    case SceneDrawing::JointKind::kUniversal: return v1::DrawingJoint::KIND_UNIVERSAL;
    case SceneDrawing::JointKind::kCylindrical: return v1::DrawingJoint::KIND_CYLINDRICAL;
    case SceneDrawing::JointKind::kPlanar: return v1::DrawingJoint::KIND_PLANAR;
    case SceneDrawing::JointKind::kPointOnPlane: return v1::DrawingJoint::KIND_POINT_ON_PLANE;
  }
  return v1::DrawingJoint::KIND_PIN;
}

SceneDrawing::JointKind KindFromProto(v1::DrawingJoint::Kind kind) {
  switch (kind) {
    case v1::DrawingJoint::KIND_SLIDER: return SceneDrawing::JointKind::kSlider;
    case v1::DrawingJoint::KIND_FIXED: return SceneDrawing::JointKind::kFixed;
    case v1::DrawingJoint::KIND_PIN_IN_SLOT: return SceneDrawing::JointKind::kPinInSlot;
    case v1::DrawingJoint::KIND_SPHERICAL: return SceneDrawing::JointKind::kSpherical;
    case v1::DrawingJoint::KIND_UNIVERSAL: return SceneDrawing::JointKind::kUniversal;
    case v1::DrawingJoint::KIND_CYLINDRICAL: return SceneDrawing::JointKind::kCylindrical;
    case v1::DrawingJoint::KIND_PLANAR: return SceneDrawing::JointKind::kPlanar;
    case v1::DrawingJoint::KIND_POINT_ON_PLANE: return SceneDrawing::JointKind::kPointOnPlane;
    default: return SceneDrawing::JointKind::kPin;
  }
}

void DirectionsToProto(const std::vector<DrawingDirection>& directions,
                       google::protobuf::RepeatedPtrField<v1::DrawingDirection>* out) {
  for (const DrawingDirection& d : directions) {
    v1::DrawingDirection* m = out->Add();
    m->set_x(d.x);
    m->set_y(d.y);
    m->set_z(d.z);
  }
}

std::vector<DrawingDirection> DirectionsFromProto(const google::protobuf::RepeatedPtrField<v1::DrawingDirection>& in) {
  std::vector<DrawingDirection> out;
  out.reserve(static_cast<size_t>(in.size()));
  for (const v1::DrawingDirection& d : in) out.push_back(DrawingDirection{d.x(), d.y(), d.z()});
  return out;
}

}  // namespace

v1::SceneDrawing DrawingToProto(const SceneDrawing& d) {
  v1::SceneDrawing m;
  m.set_scene_name(d.scene_name);
  m.set_schematic(d.schematic);
  m.mutable_times_s()->Assign(d.times_s.begin(), d.times_s.end());
  for (const std::string& name : d.point_names) m.add_point_names(name);
  for (const std::vector<DrawingPosition>& instant : d.points_m) {
    v1::DrawingInstant* out = m.add_instants();
    for (const DrawingPosition& p : instant) {
      out->add_xy_m(p.x_m);
      out->add_xy_m(p.y_m);
      if (d.spatial) out->add_z_m(p.z_m);
    }
  }
  for (const SceneDrawing::Body& b : d.bodies) {
    v1::DrawingBody* out = m.add_bodies();
    out->set_name(b.name);
    out->mutable_points()->Assign(b.points.begin(), b.points.end());
  }
  for (const SceneDrawing::Joint& j : d.joints) {
    v1::DrawingJoint* out = m.add_joints();
    out->set_name(j.name);
    out->set_kind(KindToProto(j.kind));
    out->set_point(j.point);
    out->mutable_axis_angle_rad()->Assign(j.axis_angle_rad.begin(), j.axis_angle_rad.end());
    out->set_rotational_spring(j.rotational_spring);
    out->set_rotational_damper(j.rotational_damper);
    DirectionsToProto(j.axis_directions, out->mutable_axis_directions());
    DirectionsToProto(j.second_axis_directions, out->mutable_second_axis_directions());
  }
  for (const SceneDrawing::Element& e : d.elements) {
    v1::DrawingElement* out = m.add_elements();
    out->set_name(e.name);
    out->set_a(e.a);
    out->set_b(e.b);
    out->set_spring(e.spring);
    out->set_damper(e.damper);
    out->set_bushing(e.bushing);
  }
  for (const SceneDrawing::Line& l : d.lines) {
    v1::DrawingLine* out = m.add_lines();
    out->set_name(l.name);
    out->mutable_points()->Assign(l.points.begin(), l.points.end());
  }
  for (const SceneDrawing::Input& in : d.inputs) {
    v1::DrawingInput* out = m.add_inputs();
    out->set_name(in.name);
    out->set_point(in.point);
    out->set_direction_x(in.direction_x);
    out->set_direction_y(in.direction_y);
  }
  for (const SceneDrawing::Load& load : d.loads) {
    v1::DrawingLoad* out = m.add_loads();
    out->set_name(load.name);
    out->set_kind(load.kind == SceneDrawing::LoadKind::kTorque ? v1::DrawingLoad::KIND_TORQUE
                                                               : v1::DrawingLoad::KIND_FORCE);
    out->set_point(load.point);
    out->set_direction_x(load.direction_x);
    out->set_direction_y(load.direction_y);
    out->set_direction_z(load.direction_z);
    DirectionsToProto(load.directions, out->mutable_directions());
  }
  m.mutable_ground_points()->Assign(d.ground_points.begin(), d.ground_points.end());
  m.set_failure(d.failure);
  m.set_note(d.note);
  m.set_spatial(d.spatial);
  return m;
}

absl::StatusOr<SceneDrawing> DrawingFromProto(const v1::SceneDrawing& m) {
  SceneDrawing d;
  d.scene_name = m.scene_name();
  d.schematic = m.schematic();
  d.failure = m.failure();
  d.note = m.note();
  d.spatial = m.spatial();
  d.times_s.assign(m.times_s().begin(), m.times_s().end());
  d.point_names.assign(m.point_names().begin(), m.point_names().end());
  const int points = m.point_names_size();
  if (m.instants_size() != m.times_s_size()) {
    return absl::InvalidArgumentError(absl::StrFormat("drawing '%s': %d instants for %d times_s", m.scene_name(),
                                                      m.instants_size(), m.times_s_size()));
  }
  for (int i = 0; i < m.instants_size(); ++i) {
    const v1::DrawingInstant& instant = m.instants(i);
    if (instant.xy_m_size() != 2 * points) {
      return absl::InvalidArgumentError(absl::StrFormat("drawing '%s': instants[%d].xy_m has %d values, expected %d",
                                                        m.scene_name(), i, instant.xy_m_size(), 2 * points));
    }
    const int z_values = d.spatial ? points : 0;
    if (instant.z_m_size() != z_values) {
      return absl::InvalidArgumentError(absl::StrFormat("drawing '%s': instants[%d].z_m has %d values, expected %d%s",
                                                        m.scene_name(), i, instant.z_m_size(), z_values,
                                                        d.spatial ? "" : " (not a spatial drawing)"));
    }
    std::vector<DrawingPosition>& out = d.points_m.emplace_back();
    for (int k = 0; k < points; ++k) {
      out.push_back(DrawingPosition{instant.xy_m(2 * k), instant.xy_m(2 * k + 1), d.spatial ? instant.z_m(k) : 0.0});
    }
  }
  auto check = [&](int index, const std::string& where) -> absl::Status {
    if (index < 0 || index >= points) {
      return absl::InvalidArgumentError(absl::StrFormat("drawing '%s': %s is point %d, expected 0 to %d",
                                                        m.scene_name(), where, index, points - 1));
    }
    return absl::OkStatus();
  };
  for (int b = 0; b < m.bodies_size(); ++b) {
    SceneDrawing::Body body;
    body.name = m.bodies(b).name();
    for (int k = 0; k < m.bodies(b).points_size(); ++k) {
      const absl::Status s = check(m.bodies(b).points(k), absl::StrFormat("bodies[%d].points[%d]", b, k));
      if (!s.ok()) return s;
      body.points.push_back(m.bodies(b).points(k));
    }
    d.bodies.push_back(std::move(body));
  }
  for (int j = 0; j < m.joints_size(); ++j) {
    const v1::DrawingJoint& in = m.joints(j);
    if (absl::Status s = check(in.point(), absl::StrFormat("joints[%d].point", j)); !s.ok()) return s;
    SceneDrawing::Joint joint{in.name(),
                              KindFromProto(in.kind()),
                              in.point(),
                              std::vector<double>(in.axis_angle_rad().begin(), in.axis_angle_rad().end()),
                              in.rotational_spring(),
                              in.rotational_damper(),
                              DirectionsFromProto(in.axis_directions()),
                              DirectionsFromProto(in.second_axis_directions())};
    // A spatial drawing gives its axes as directions (checked below).
    const bool axis = !d.spatial && (joint.kind == SceneDrawing::JointKind::kSlider ||
                                     joint.kind == SceneDrawing::JointKind::kPinInSlot);
    if (axis && in.axis_angle_rad_size() != m.times_s_size()) {
      return absl::InvalidArgumentError(
          absl::StrFormat("drawing '%s': joints[%d].axis_angle_rad has %d values, expected %d", m.scene_name(), j,
                          in.axis_angle_rad_size(), m.times_s_size()));
    }
    // A spatial joint's axes: one per instant, or none (a spherical or
    // fixed joint; a planar drawing).
    for (const auto* directions : {&joint.axis_directions, &joint.second_axis_directions}) {
      if (!directions->empty() && directions->size() != d.times_s.size()) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "drawing '%s': joints[%d].%s has %d values, expected %d", m.scene_name(), j,
            directions == &joint.axis_directions ? "axis_directions" : "second_axis_directions", directions->size(),
            d.times_s.size()));
      }
    }
    d.joints.push_back(std::move(joint));
  }
  for (int e = 0; e < m.elements_size(); ++e) {
    const v1::DrawingElement& in = m.elements(e);
    if (absl::Status s = check(in.a(), absl::StrFormat("elements[%d].a", e)); !s.ok()) return s;
    if (absl::Status s = check(in.b(), absl::StrFormat("elements[%d].b", e)); !s.ok()) return s;
    d.elements.push_back(SceneDrawing::Element{in.name(), in.a(), in.b(), in.spring(), in.damper(), in.bushing()});
  }
  for (int l = 0; l < m.lines_size(); ++l) {
    SceneDrawing::Line line;
    line.name = m.lines(l).name();
    for (int k = 0; k < m.lines(l).points_size(); ++k) {
      const absl::Status s = check(m.lines(l).points(k), absl::StrFormat("lines[%d].points[%d]", l, k));
      if (!s.ok()) return s;
      line.points.push_back(m.lines(l).points(k));
    }
    d.lines.push_back(std::move(line));
  }
  for (int i = 0; i < m.inputs_size(); ++i) {
    const v1::DrawingInput& in = m.inputs(i);
    if (absl::Status s = check(in.point(), absl::StrFormat("inputs[%d].point", i)); !s.ok()) return s;
    d.inputs.push_back(SceneDrawing::Input{in.name(), in.point(), in.direction_x(), in.direction_y()});
  }
  for (int i = 0; i < m.loads_size(); ++i) {
    const v1::DrawingLoad& in = m.loads(i);
    if (absl::Status s = check(in.point(), absl::StrFormat("loads[%d].point", i)); !s.ok()) return s;
    d.loads.push_back(SceneDrawing::Load{
        in.name(), in.kind() == v1::DrawingLoad::KIND_TORQUE ? SceneDrawing::LoadKind::kTorque : SceneDrawing::LoadKind::kForce,
        in.point(), in.direction_x(), in.direction_y(), in.direction_z(), DirectionsFromProto(in.directions())});
    if (!d.loads.back().directions.empty() && d.loads.back().directions.size() != d.times_s.size()) {
      return absl::InvalidArgumentError(absl::StrFormat("drawing '%s': loads[%d].directions has %d values, expected %d",
                                                        m.scene_name(), i, d.loads.back().directions.size(),
                                                        d.times_s.size()));
    }
  }
  for (int g = 0; g < m.ground_points_size(); ++g) {
    if (absl::Status s = check(m.ground_points(g), absl::StrFormat("ground_points[%d]", g)); !s.ok()) return s;
    d.ground_points.push_back(m.ground_points(g));
  }
  return d;
}

}  // namespace mbopt::spec::io
