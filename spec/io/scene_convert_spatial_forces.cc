// A `spatial` model's force elements beyond springs and gravity (point
// forces, torques, rotational spring-dampers, bushings) and the outputs that
// read them or the joints' multipliers.
#include <set>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "spec/io/declared_name.h"
#include "spec/io/scene_converter.h"

namespace mbopt::spec::io {
namespace {

constexpr const char* kAxesExpected = "expected SPATIAL_LOAD_WORLD_AXES or SPATIAL_LOAD_BODY_AXES";

// Checks a load's axes field; true for the body's axes.
bool BodyAxes(const Where& w, v1::SpatialLoadAxes axes, Errors* errors) {
  switch (axes) {
    case v1::SPATIAL_LOAD_WORLD_AXES: return false;
    case v1::SPATIAL_LOAD_BODY_AXES: return true;
    default: errors->Add(w, "axes", kAxesExpected); return false;
  }
}

}  // namespace

template <class Message>
std::optional<TimeFactor> SceneConverter::SpatialLoadFactor(const Where& w, const Message& m) {
  TimeFactor factor;
  switch (m.factor_case()) {
    case Message::kHarmonic: Harmonic(w.Child("harmonic"), m.harmonic(), &factor); return factor;
    case Message::kTabulated: Tabulated(w.Child("tabulated"), m.tabulated(), &factor); return factor;
    default: return std::nullopt;
  }
}

void SceneConverter::ConvertSpatialForces(const v1::SpatialModel& m, const Where& w) {
  // The springs' force curves and actuator force (the springs themselves
  // are converted with the rest of the model).
  for (int i = 0; i < m.springs_size() && i < static_cast<int>(spatial_.springs.size()); ++i) {
    const v1::SpatialSpring& sp = m.springs(i);
    const Where sw = w.Child("springs", i);
    SpatialSpring& spring = spatial_.springs[static_cast<size_t>(i)];
    spring.actuator_force_n =
        Num(sw, "actuator_force_n", sp.has_actuator_force_n(), sp.actuator_force_n(), Dimension::kForce, 0.0);
    if (sp.has_deflection_curve()) {
      spring.deflection_m.assign(sp.deflection_curve().x().begin(), sp.deflection_curve().x().end());
      spring.deflection_force_n.assign(sp.deflection_curve().force_n().begin(), sp.deflection_curve().force_n().end());
      CheckTable(sw.Child("deflection_curve"), "x", "force_n", spring.deflection_m, spring.deflection_force_n);
    }
    if (sp.has_velocity_curve()) {
      spring.velocity_m_per_s.assign(sp.velocity_curve().x().begin(), sp.velocity_curve().x().end());
      spring.velocity_force_n.assign(sp.velocity_curve().force_n().begin(), sp.velocity_curve().force_n().end());
      CheckTable(sw.Child("velocity_curve"), "x", "force_n", spring.velocity_m_per_s, spring.velocity_force_n);
    }
  }
  std::set<std::string> load_names;
  for (int i = 0; i < m.point_forces_size(); ++i) {
    const v1::SpatialPointForce& f = m.point_forces(i);
    const Where fw = w.Child("point_forces", i);
    SpatialPointForce force;
    force.name = f.name();
    CheckDeclaredName(fw, f.name(), load_names.insert(f.name()).second,
                      {.missing = "a point force needs a name", .duplicate = "load name"}, &errors_);
    force.at = SpatialMarkerOf(fw, "at", f.at());
    if (!f.has_force_n()) errors_.Add(fw, "force_n", "missing: expected e.g. `{ z { value: -100 } }` (N)");
    force.force_n = Vec3Of(fw, "force_n", f.has_force_n(), f.force_n(), Dimension::kForce);
    force.body_axes = BodyAxes(fw, f.axes(), &errors_);
    force.factor = SpatialLoadFactor(fw, f);
    spatial_.point_forces.push_back(std::move(force));
  }
  for (int i = 0; i < m.torques_size(); ++i) {
    const v1::SpatialTorque& t = m.torques(i);
    const Where tw = w.Child("torques", i);
    SpatialTorque torque;
    torque.name = t.name();
    CheckDeclaredName(tw, t.name(), load_names.insert(t.name()).second,
                      {.missing = "a torque needs a name", .duplicate = "load name"}, &errors_);
    auto it = spatial_bodies_.find(t.body());
    if (it == spatial_bodies_.end()) {
      errors_.Add(tw, "body", absl::StrCat("unknown body \"", t.body(), "\" (bodies: ",
                                           absl::StrJoin(Names(spatial_bodies_), ", "), ")"));
    } else {
      torque.body = it->second;
    }
    if (!t.has_torque_n_m()) errors_.Add(tw, "torque_n_m", "missing: expected e.g. `{ z { value: 5 } }` (N m)");
    torque.torque_n_m = Vec3Of(tw, "torque_n_m", t.has_torque_n_m(), t.torque_n_m(), Dimension::kTorque);
    torque.body_axes = BodyAxes(tw, t.axes(), &errors_);
    torque.factor = SpatialLoadFactor(tw, t);
    spatial_.torques.push_back(std::move(torque));
  }
  for (int i = 0; i < m.rotational_springs_size(); ++i) {
    const v1::SpatialRotationalSpring& r = m.rotational_springs(i);
    const Where rw = w.Child("rotational_springs", i);
    SpatialRotationalSpring spring;
    spring.name = r.name();
    CheckDeclaredName(rw, r.name(), spatial_rotational_springs_.emplace(r.name(), i).second,
                      {.missing = "a rotational spring needs a name", .duplicate = "rotational spring name"},
                      &errors_);
    spring.joint = SpatialJointIndex(rw, "joint", r.joint());
    if (spring.joint >= 0) {
      const SpatialJointKind kind = spatial_.joints[static_cast<size_t>(spring.joint)].kind;
      if (kind != SpatialJointKind::kRevolute && kind != SpatialJointKind::kCylindrical) {
        errors_.Add(rw, "joint",
                    absl::StrCat("joint \"", r.joint(),
                                 "\" is not revolute or cylindrical: a rotational spring acts on such a joint's angle"));
      }
    }
    spring.stiffness_n_m_per_rad = Num(rw, "stiffness_n_m_per_rad", r.has_stiffness_n_m_per_rad(),
                                       r.stiffness_n_m_per_rad(), Dimension::kRotationalStiffness, 0.0);
    RequireNotNegative(rw, "stiffness_n_m_per_rad", spring.stiffness_n_m_per_rad);
    spring.damping_n_m_s_per_rad = Num(rw, "damping_n_m_s_per_rad", r.has_damping_n_m_s_per_rad(),
                                       r.damping_n_m_s_per_rad(), Dimension::kRotationalDamping, 0.0);
    RequireNotNegative(rw, "damping_n_m_s_per_rad", spring.damping_n_m_s_per_rad);
    spring.free_angle_rad =
        Num(rw, "free_angle_rad", r.has_free_angle_rad(), r.free_angle_rad(), Dimension::kAngle, 0.0);
    spatial_.rotational_springs.push_back(std::move(spring));
  }
  for (int i = 0; i < m.bushings_size(); ++i) {
    const v1::SpatialBushing& b = m.bushings(i);
    const Where bw = w.Child("bushings", i);
    SpatialBushing bushing;
    bushing.name = b.name();
    CheckDeclaredName(bw, b.name(), spatial_bushings_.emplace(b.name(), i).second,
                      {.missing = "a bushing needs a name", .duplicate = "bushing name"}, &errors_);
    bushing.a = SpatialMarkerOf(bw, "a", b.a());
    bushing.b = SpatialMarkerOf(bw, "b", b.b());
    if (bushing.a.marker >= 0 && bushing.b.marker >= 0 && bushing.a.body == bushing.b.body) {
      errors_.Add(bw, "b", "a bushing joins two different bodies (or a body and ground)");
    }
    auto coefficients = [&](const char* field, bool present, const v1::Vector3& v, Dimension dimension) {
      const Vec3 out = Vec3Of(bw, field, present, v, dimension);
      const Where cw = bw.Child(field);
      RequireNotNegative(cw, "x", out.x);
      RequireNotNegative(cw, "y", out.y);
      RequireNotNegative(cw, "z", out.z);
      return out;
    };
    bushing.stiffness_n_per_m =
        coefficients("stiffness_n_per_m", b.has_stiffness_n_per_m(), b.stiffness_n_per_m(), Dimension::kStiffness);
    bushing.damping_n_s_per_m =
        coefficients("damping_n_s_per_m", b.has_damping_n_s_per_m(), b.damping_n_s_per_m(), Dimension::kDamping);
    bushing.rotational_stiffness_n_m_per_rad =
        coefficients("rotational_stiffness_n_m_per_rad", b.has_rotational_stiffness_n_m_per_rad(),
                     b.rotational_stiffness_n_m_per_rad(), Dimension::kRotationalStiffness);
    bushing.rotational_damping_n_m_s_per_rad =
        coefficients("rotational_damping_n_m_s_per_rad", b.has_rotational_damping_n_m_s_per_rad(),
                     b.rotational_damping_n_m_s_per_rad(), Dimension::kRotationalDamping);
    spatial_.bushings.push_back(std::move(bushing));
  }
}

bool SceneConverter::SpatialForceOutputOf(const v1::Output& o, const Where& ow, SpatialOutput* out) {
  using Q = SpatialOutput::Quantity;
  auto axis_of = [&](const Where& kw, v1::Axis axis) {
    switch (axis) {
      case v1::AXIS_X: return Axis::kX;
      case v1::AXIS_Y: return Axis::kY;
      case v1::AXIS_Z: return Axis::kZ;
      default: errors_.Add(kw, "axis", "expected AXIS_X, AXIS_Y or AXIS_Z"); return Axis::kX;
    }
  };
  // Reactions of any joint (a driver's effort: scene_convert_spatial.cc).
  auto joint = [&](const char* field, const v1::JointOutput& j, Q quantity) {
    const Where kw = ow.Child(field);
    out->quantity = quantity;
    out->joint = SpatialJointIndex(kw, "joint", j.joint());
    out->axis = axis_of(kw, j.axis());
  };
  switch (o.kind_case()) {
    case v1::Output::kBodyAngularVelocity: {
      const Where kw = ow.Child("body_angular_velocity");
      const v1::BodyAngularVelocityOutput& b = o.body_angular_velocity();
      out->quantity = Q::kBodyAngularVelocity;
      auto it = spatial_bodies_.find(b.body());
      if (it == spatial_bodies_.end()) {
        errors_.Add(kw, "body", absl::StrCat("unknown body \"", b.body(), "\" (bodies: ",
                                             absl::StrJoin(Names(spatial_bodies_), ", "), ")"));
      } else {
        out->body = it->second;
      }
      out->axis = axis_of(kw, b.axis());
      out->body_axes = b.body_axes();
      return true;
    }
    case v1::Output::kJointReaction: joint("joint_reaction", o.joint_reaction(), Q::kJointReaction); return true;
    case v1::Output::kJointReactionMoment:
      joint("joint_reaction_moment", o.joint_reaction_moment(), Q::kJointReactionMoment);
      return true;
    case v1::Output::kBushingForce: {
      const Where kw = ow.Child("bushing_force");
      const v1::BushingOutput& b = o.bushing_force();
      out->quantity = b.moment() ? Q::kBushingMoment : Q::kBushingForce;
      auto it = spatial_bushings_.find(b.bushing());
      if (it == spatial_bushings_.end()) {
        errors_.Add(kw, "bushing", absl::StrCat("unknown bushing \"", b.bushing(), "\" (bushings: ",
                                                spatial_bushings_.empty() ? "none"
                                                                          : absl::StrJoin(Names(spatial_bushings_), ", "),
                                                ")"));
      } else {
        out->bushing = it->second;
      }
      out->axis = axis_of(kw, b.axis());
      return true;
    }
    case v1::Output::kRotationalSpringTorque: {
      const Where kw = ow.Child("rotational_spring_torque");
      out->quantity = Q::kRotationalSpringTorque;
      auto it = spatial_rotational_springs_.find(o.rotational_spring_torque().spring());
      if (it == spatial_rotational_springs_.end()) {
        errors_.Add(kw, "spring",
                    absl::StrCat("unknown rotational spring \"", o.rotational_spring_torque().spring(),
                                 "\" (rotational springs: ",
                                 spatial_rotational_springs_.empty() ? "none"
                                                                     : absl::StrJoin(Names(spatial_rotational_springs_), ", "),
                                 ")"));
      } else {
        out->spring = it->second;
      }
      return true;
    }
    default: return false;
  }
}

}  // namespace mbopt::spec::io
