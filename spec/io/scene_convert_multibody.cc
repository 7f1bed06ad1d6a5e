// A `multibody` model: bodies, flexible links, joints, drivers, springs,
// forces and input points, and the outputs read from it.
#include "spec/io/scene_converter.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "spec/io/declared_name.h"
#include "spec/limits.h"

namespace mbopt::spec::io {

// "body.marker" or "ground.marker" to a marker reference.
MarkerRef SceneConverter::Marker(const Where& w, const std::string& field, const std::string& ref) {
  MarkerRef out;
  const size_t dot = ref.find('.');
  if (dot == std::string::npos) {
    errors_.Add(w, field, absl::StrCat("\"", ref, "\": expected \"body.marker\" or \"ground.marker\""));
    return out;
  }
  const std::string body = ref.substr(0, dot), marker = ref.substr(dot + 1);
  if (body == "input") {
    auto it = multibody_inputs_.find(marker);
    if (it == multibody_inputs_.end()) {
      errors_.Add(w, field, absl::StrCat("unknown input point \"", marker, "\" (inputs: ",
                                         multibody_inputs_.empty() ? "none" : absl::StrJoin(Names(multibody_inputs_), ", "),
                                         ")"));
    } else {
      out.input = it->second;
      out.marker = 0;  // resolved
    }
    return out;
  }
  if (auto link = multibody_links_.find(body); link != multibody_links_.end()) {
    out.link = link->second;
    if (marker == "a" || marker == "b") {
      out.marker = marker == "a" ? 0 : 1;
    } else {
      errors_.Add(w, field, absl::StrCat("flexible link \"", body, "\" has ends \"a\" and \"b\", not \"", marker,
                                         "\""));
    }
    return out;
  }
  const std::vector<LinkPoint>* markers = &multibody_.ground_markers;
  if (body != "ground") {
    auto it = multibody_bodies_.find(body);
    if (it == multibody_bodies_.end()) {
      errors_.Add(w, field, absl::StrCat("unknown body \"", body, "\" in \"", ref, "\" (bodies: ",
                                         absl::StrJoin(Names(multibody_bodies_), ", "), ")"));
      return out;
    }
    out.body = it->second;
    markers = &multibody_.bodies[static_cast<size_t>(out.body)].markers;
  }
  for (size_t k = 0; k < markers->size(); ++k) {
    if ((*markers)[k].name == marker) out.marker = static_cast<int>(k);
  }
  if (out.marker < 0) {
    std::vector<std::string> names;
    for (const LinkPoint& p : *markers) names.push_back(p.name);
    errors_.Add(w, field, absl::StrCat("\"", body, "\" has no marker \"", marker, "\" (markers: ",
                                       names.empty() ? "none" : absl::StrJoin(names, ", "), ")"));
  }
  return out;
}

std::vector<std::string> SceneConverter::Names(const std::map<std::string, int>& table) {
  std::vector<std::pair<int, std::string>> ordered;
  for (const auto& [name, index] : table) ordered.emplace_back(index, name);
  std::sort(ordered.begin(), ordered.end());
  std::vector<std::string> names;
  for (const auto& [index, name] : ordered) names.push_back(name);
  return names;
}

std::vector<LinkPoint> SceneConverter::Markers(const Where& w, const std::string& field,
                               const google::protobuf::RepeatedPtrField<v1::Marker>& markers) {
  std::vector<LinkPoint> out;
  std::set<std::string> names;
  for (int k = 0; k < markers.size(); ++k) {
    const Where mw = w.Child(field, k);
    LinkPoint p;
    p.name = markers[k].name();
    CheckDeclaredName(mw, p.name, names.insert(p.name).second,
                      {.missing = "a marker needs a name", .duplicate = "marker"}, &errors_);
    p.position_m = Vec(mw, "position_m", markers[k].has_position_m(), markers[k].position_m(), Dimension::kLength);
    out.push_back(std::move(p));
  }
  return out;
}

int SceneConverter::MultibodyJointIndex(const Where& w, const std::string& field, const std::string& name) {
  auto it = multibody_joints_.find(name);
  if (it == multibody_joints_.end()) {
    errors_.Add(w, field, absl::StrCat("unknown joint \"", name, "\" (joints: ",
                                       absl::StrJoin(Names(multibody_joints_), ", "), ")"));
    return -1;
  }
  return it->second;
}

MultibodyModel SceneConverter::ConvertMultibody(const v1::MultibodyModel& m, const Where& w) {
  multibody_ = MultibodyModel{};
  switch (m.analysis()) {
    case v1::MULTIBODY_ANALYSIS_FROM_DEGREES_OF_FREEDOM: break;
    case v1::MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM:
      multibody_.analysis = MultibodyModel::Analysis::kStaticEquilibrium;
      break;
    default:
      errors_.Add(w, "analysis",
                  "expected MULTIBODY_ANALYSIS_FROM_DEGREES_OF_FREEDOM or MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM");
      break;
  }
  multibody_.ground_markers = Markers(w, "ground_markers", m.ground_markers());
  for (int i = 0; i < m.inputs_size(); ++i) {
    const v1::InputPoint& in = m.inputs(i);
    const Where iw = w.Child("inputs", i);
    MultibodyInput input;
    input.name = in.name();
    CheckDeclaredName(iw, in.name(), multibody_inputs_.emplace(in.name(), i).second,
                      {.missing = "an input point needs a name", .duplicate = "input name"}, &errors_);
    input.position_m = Vec(iw, "position_m", in.has_position_m(), in.position_m(), Dimension::kLength);
    Direction(iw, "direction", in.has_direction(), in.direction(), &input.direction_x, &input.direction_y);
    if (in.has_harmonic()) {
      Harmonic(iw.Child("harmonic"), in.harmonic(), &input.displacement);
    } else if (in.has_tabulated()) {
      Tabulated(iw.Child("tabulated"), in.tabulated(), &input.displacement);
    } else {
      errors_.Add(iw, "", "an input point needs a displacement: `harmonic { ... }` or `tabulated { ... }`");
    }
    multibody_.inputs.push_back(std::move(input));
  }
  for (int i = 0; i < m.bodies_size(); ++i) {
    const v1::RigidBody& b = m.bodies(i);
    const Where bw = w.Child("bodies", i);
    RigidBody body;
    body.name = b.name();
    CheckDeclaredName(bw, b.name(), multibody_bodies_.emplace(b.name(), i).second,
                      {.missing = "a body needs a name other than \"ground\"",
                       .duplicate = "body name",
                       .reserved = {"ground"}},
                      &errors_);
    body.mass_kg = Num(bw, "mass_kg", b.has_mass_kg(), b.mass_kg(), Dimension::kMass);
    RequirePositive(bw, "mass_kg", body.mass_kg);
    body.inertia_kg_m2 = Num(bw, "inertia_kg_m2", b.has_inertia_kg_m2(), b.inertia_kg_m2(), Dimension::kInertia);
    RequirePositive(bw, "inertia_kg_m2", body.inertia_kg_m2);
    body.position_m = Vec(bw, "position_m", b.has_position_m(), b.position_m(), Dimension::kLength);
    body.angle_rad = Num(bw, "angle_rad", b.has_angle_rad(), b.angle_rad(), Dimension::kAngle, 0.0);
    body.markers = Markers(bw, "markers", b.markers());
    multibody_.bodies.push_back(std::move(body));
  }
  for (int i = 0; i < m.flexible_links_size(); ++i) {
    const v1::FlexibleBeamLink& l = m.flexible_links(i);
    const Where lw = w.Child("flexible_links", i);
    MultibodyFlexibleLink link;
    link.name = l.name();
    // Bodies and flexible links share one namespace (markers name either).
    CheckDeclaredName(lw, l.name(),
                      multibody_bodies_.count(l.name()) == 0 && multibody_links_.emplace(l.name(), i).second,
                      {.missing = "a flexible link needs a name other than \"ground\" and \"input\"",
                       .duplicate = "body or link name",
                       .reserved = {"ground", "input"}},
                      &errors_);
    link.start_m = Vec(lw, "start_m", l.has_start_m(), l.start_m(), Dimension::kLength);
    link.angle_rad = Num(lw, "angle_rad", l.has_angle_rad(), l.angle_rad(), Dimension::kAngle, 0.0);
    link.length_m = Num(lw, "length_m", l.has_length_m(), l.length_m(), Dimension::kLength);
    RequirePositive(lw, "length_m", link.length_m);
    if (!l.has_section()) errors_.Add(lw, "section", "a flexible link needs a section (area, modulus, density)");
    link.section = ConvertSection(lw.Child("section"), l.section());
    link.elements = l.elements() == 0 ? 4 : l.elements();
    link.rotary_inertia = l.rotary_inertia();
    if (link.elements < 1 || link.elements > kMaxFlexibleLinkElements) {
      errors_.Add(lw, "elements", absl::StrFormat("expected 1 to %d elements (0 for the default 4), got %d",
                                                  kMaxFlexibleLinkElements, l.elements()));
    }
    multibody_.flexible_links.push_back(std::move(link));
  }
  if (m.bodies_size() == 0 && m.flexible_links_size() == 0) {
    errors_.Add(w, "bodies", "a multibody model needs at least one body or flexible link");
  }
  for (int i = 0; i < m.joints_size(); ++i) {
    const v1::MultibodyJoint& j = m.joints(i);
    const Where jw = w.Child("joints", i);
    MultibodyJoint joint;
    joint.name = j.name();
    CheckDeclaredName(jw, j.name(), multibody_joints_.emplace(j.name(), i).second,
                      {.missing = "a joint needs a name", .duplicate = "joint name"}, &errors_);
    switch (j.kind()) {
      case v1::JOINT_REVOLUTE: joint.kind = JointKind::kRevolute; break;
      case v1::JOINT_PRISMATIC: joint.kind = JointKind::kPrismatic; break;
      case v1::JOINT_FIXED: joint.kind = JointKind::kFixed; break;
      case v1::JOINT_POINT_ON_LINE: joint.kind = JointKind::kPointOnLine; break;
      default:
        errors_.Add(jw, "kind", "expected JOINT_REVOLUTE, JOINT_PRISMATIC, JOINT_FIXED or JOINT_POINT_ON_LINE");
    }
    joint.a = Marker(jw, "a", j.a());
    joint.b = Marker(jw, "b", j.b());
    if (joint.a.input >= 0 || joint.b.input >= 0) {
      errors_.Add(jw, joint.a.input >= 0 ? "a" : "b",
                  "an input point takes springs and forces, not joints (it is not a body)");
    }
    const bool same_body = joint.a.link >= 0 || joint.b.link >= 0
                               ? joint.a.link == joint.b.link && joint.a.marker == joint.b.marker
                               : joint.a.body == joint.b.body;
    if (joint.a.marker >= 0 && joint.b.marker >= 0 && same_body) {
      errors_.Add(jw, "b", "a joint joins two different bodies (or a body and ground)");
    }
    joint.axis_angle_rad = Num(jw, "axis_angle_rad", j.has_axis_angle_rad(), j.axis_angle_rad(), Dimension::kAngle, 0.0);
    const Dimension coordinate = joint.linear() ? Dimension::kLength : Dimension::kAngle;
    if (j.has_initial_value()) joint.initial_value = Num(jw, "initial_value", true, j.initial_value(), coordinate);
    if (j.has_initial_rate()) joint.initial_rate = Num(jw, "initial_rate", true, j.initial_rate(), Dimension::kAny);
    multibody_.joints.push_back(std::move(joint));
  }
  std::set<int> driven;
  for (int i = 0; i < m.drivers_size(); ++i) {
    const v1::MultibodyDriver& d = m.drivers(i);
    const Where dw = w.Child("drivers", i);
    MultibodyDriver driver;
    driver.joint = MultibodyJointIndex(dw, "joint", d.joint());
    if (driver.joint >= 0) {
      if (multibody_.joints[static_cast<size_t>(driver.joint)].kind == JointKind::kFixed) {
        errors_.Add(dw, "joint", "a fixed joint cannot be driven");
      }
      if (!driven.insert(driver.joint).second) errors_.Add(dw, "joint", "this joint already has a driver");
    }
    switch (d.profile_case()) {
      case v1::MultibodyDriver::kConstantRate: {
        const Where pw = dw.Child("constant_rate");
        driver.profile = MultibodyDriver::Profile::kConstantRate;
        driver.start = Num(pw, "start", d.constant_rate().has_start(), d.constant_rate().start(), Dimension::kAny, 0.0);
        driver.rate = Num(pw, "rate", d.constant_rate().has_rate(), d.constant_rate().rate(), Dimension::kAny);
        break;
      }
      case v1::MultibodyDriver::kPolynomial: {
        const Where pw = dw.Child("polynomial");
        driver.profile = MultibodyDriver::Profile::kPolynomial;
        for (int k = 0; k < d.polynomial().coefficients_size(); ++k) {
          driver.coefficients.push_back(Num(pw, absl::StrCat("coefficients[", k, "]"), true, d.polynomial().coefficients(k), Dimension::kAny));
        }
        if (driver.coefficients.empty()) errors_.Add(pw, "coefficients", "a polynomial needs at least one coefficient");
        break;
      }
      case v1::MultibodyDriver::kHarmonic:
        Harmonic(dw.Child("harmonic"), d.harmonic(), &driver);
        break;
      case v1::MultibodyDriver::kTabulated:
        Tabulated(dw.Child("tabulated"), d.tabulated(), &driver);
        break;
      case v1::MultibodyDriver::PROFILE_NOT_SET:
        errors_.Add(dw, "", "a driver needs a profile: `constant_rate`, `polynomial` or `harmonic`");
        break;
    }
    multibody_.drivers.push_back(std::move(driver));
  }
  for (int i = 0; i < m.springs_size(); ++i) {
    const v1::MultibodySpring& sp = m.springs(i);
    const Where sw = w.Child("springs", i);
    MultibodySpring spring;
    spring.name = sp.name();
    CheckDeclaredName(sw, sp.name(), multibody_springs_.emplace(sp.name(), i).second,
                      {.missing = "a spring needs a name", .duplicate = "spring name"}, &errors_);
    spring.a = Marker(sw, "a", sp.a());
    spring.b = Marker(sw, "b", sp.b());
    spring.free_length_m = Num(sw, "free_length_m", sp.has_free_length_m(), sp.free_length_m(), Dimension::kLength, 0.0);
    RequireNotNegative(sw, "free_length_m", spring.free_length_m);
    spring.stiffness_n_per_m = Num(sw, "stiffness_n_per_m", sp.has_stiffness_n_per_m(), sp.stiffness_n_per_m(), Dimension::kStiffness, 0.0);
    spring.damping_n_s_per_m = Num(sw, "damping_n_s_per_m", sp.has_damping_n_s_per_m(), sp.damping_n_s_per_m(), Dimension::kDamping, 0.0);
    spring.actuator_force_n = Num(sw, "actuator_force_n", sp.has_actuator_force_n(), sp.actuator_force_n(), Dimension::kForce, 0.0);
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
    multibody_.springs.push_back(std::move(spring));
  }
  for (int i = 0; i < m.rotational_springs_size(); ++i) {
    const v1::RotationalSpring& r = m.rotational_springs(i);
    const Where rw = w.Child("rotational_springs", i);
    RotationalSpring spring;
    spring.name = r.name();
    spring.joint = MultibodyJointIndex(rw, "joint", r.joint());
    if (spring.joint >= 0 && multibody_.joints[static_cast<size_t>(spring.joint)].kind != JointKind::kRevolute) {
      errors_.Add(rw, "joint", "a rotational spring acts at a revolute joint");
    }
    spring.stiffness_n_m_per_rad = Num(rw, "stiffness_n_m_per_rad", r.has_stiffness_n_m_per_rad(), r.stiffness_n_m_per_rad(), Dimension::kRotationalStiffness, 0.0);
    spring.damping_n_m_s_per_rad = Num(rw, "damping_n_m_s_per_rad", r.has_damping_n_m_s_per_rad(), r.damping_n_m_s_per_rad(), Dimension::kRotationalDamping, 0.0);
    spring.free_angle_rad = Num(rw, "free_angle_rad", r.has_free_angle_rad(), r.free_angle_rad(), Dimension::kAngle, 0.0);
    multibody_.rotational_springs.push_back(std::move(spring));
  }
  for (int i = 0; i < m.point_forces_size(); ++i) {
    const Where fw = w.Child("point_forces", i);
    MultibodyPointForce force;
    force.at = Marker(fw, "at", m.point_forces(i).at());
    force.force_n = Vec(fw, "force_n", m.point_forces(i).has_force_n(), m.point_forces(i).force_n(), Dimension::kForce);
    force.factor = Factor(fw, m.point_forces(i));
    multibody_.point_forces.push_back(std::move(force));
  }
  for (int i = 0; i < m.torques_size(); ++i) {
    const Where tw = w.Child("torques", i);
    MultibodyTorque torque;
    auto it = multibody_bodies_.find(m.torques(i).body());
    if (it == multibody_bodies_.end()) {
      errors_.Add(tw, "body", absl::StrCat("unknown body \"", m.torques(i).body(), "\""));
    } else {
      torque.body = it->second;
    }
    torque.torque_n_m = Num(tw, "torque_n_m", m.torques(i).has_torque_n_m(), m.torques(i).torque_n_m(), Dimension::kTorque);
    torque.factor = Factor(tw, m.torques(i));
    multibody_.torques.push_back(std::move(torque));
  }
  return multibody_;
}

void SceneConverter::Harmonic(const Where& pw, const v1::HarmonicProfile& h, MultibodyDriver* out) {
  out->profile = MultibodyDriver::Profile::kHarmonic;
  out->start = Num(pw, "mean", h.has_mean(), h.mean(), Dimension::kAny, 0.0);
  out->amplitude = Num(pw, "amplitude", h.has_amplitude(), h.amplitude(), Dimension::kAny);
  out->angular_frequency_rad_per_s = Num(pw, "angular_frequency_rad_per_s", h.has_angular_frequency_rad_per_s(),
                                         h.angular_frequency_rad_per_s(), Dimension::kAngularVelocity);
  out->phase_rad = Num(pw, "phase_rad", h.has_phase_rad(), h.phase_rad(), Dimension::kAngle, 0.0);
}

// A table that must cover the motion, from 0 to the time grid's end.
void SceneConverter::Tabulated(const Where& pw, const v1::TabulatedProfile& t, MultibodyDriver* out) {
  out->profile = MultibodyDriver::Profile::kTabulated;
  out->times_s.assign(t.times_s().begin(), t.times_s().end());
  out->values.assign(t.values().begin(), t.values().end());
  if (CheckTable(pw, "times_s", "values", out->times_s, out->values) && msg_.has_time_grid() &&
      (out->times_s.front() > 0.0 || out->times_s.back() < msg_.time_grid().end_s())) {
    errors_.Add(pw, "times_s",
                absl::StrFormat("the table covers %g..%g s; it must cover the motion from 0 to the time "
                                "grid's end, %g s",
                                out->times_s.front(), out->times_s.back(), msg_.time_grid().end_s()));
  }
}

// The optional time factor of a point force or a torque.
template <class Message>
std::optional<TimeFactor> SceneConverter::Factor(const Where& w, const Message& m) {
  TimeFactor factor;
  if (m.has_harmonic()) {
    Harmonic(w.Child("harmonic"), m.harmonic(), &factor);
    return factor;
  }
  if (m.has_tabulated()) {
    Tabulated(w.Child("tabulated"), m.tabulated(), &factor);
    return factor;
  }
  return std::nullopt;
}

// A table of at least two finite points, abscissae strictly increasing.
bool SceneConverter::CheckTable(const Where& w, const std::string& x_field, const std::string& y_field, const std::vector<double>& x,
                const std::vector<double>& y) {
  if (x.size() < 2 || x.size() != y.size()) {
    errors_.Add(w, x_field, absl::StrFormat("a table needs at least 2 points and as many %s as %s (got %d and %d)",
                                            x_field, y_field, x.size(), y.size()));
    return false;
  }
  for (size_t k = 0; k < x.size(); ++k) {
    if (!std::isfinite(x[k]) || !std::isfinite(y[k])) {
      errors_.Add(w, x_field, absl::StrFormat("point %d is not finite", k));
      return false;
    }
    if (k > 0 && !(x[k] > x[k - 1])) {
      errors_.Add(w, x_field, absl::StrFormat("must increase strictly: %g after %g (point %d)", x[k], x[k - 1], k));
      return false;
    }
  }
  return true;
}

MultibodyOutput SceneConverter::MultibodyOutputOf(const v1::Output& o, const Where& ow) {
  using Q = MultibodyOutput::Quantity;
  MultibodyOutput out;
  auto marker = [&](const char* field, const v1::MarkerOutput& m, Q quantity) {
    const Where kw = ow.Child(field);
    out.quantity = quantity;
    out.marker = Marker(kw, "marker", m.marker());
    out.axis = m.axis() == v1::AXIS_Y ? Axis::kY : Axis::kX;
    if (m.axis() != v1::AXIS_X && m.axis() != v1::AXIS_Y) errors_.Add(kw, "axis", "expected AXIS_X or AXIS_Y");
  };
  auto joint = [&](const char* field, const v1::JointOutput& j, Q quantity, bool needs_axis) {
    const Where kw = ow.Child(field);
    out.quantity = quantity;
    out.joint = MultibodyJointIndex(kw, "joint", j.joint());
    if (out.joint >= 0) out.linear = multibody_.joints[static_cast<size_t>(out.joint)].linear();
    if (needs_axis) {
      out.axis = j.axis() == v1::AXIS_Y ? Axis::kY : Axis::kX;
      if (j.axis() != v1::AXIS_X && j.axis() != v1::AXIS_Y) errors_.Add(kw, "axis", "expected AXIS_X or AXIS_Y");
    }
    if (quantity == Q::kDriverEffort && out.joint >= 0) {
      bool driven = false;
      for (const MultibodyDriver& d : multibody_.drivers) driven = driven || d.joint == out.joint;
      if (!driven) errors_.Add(kw, "joint", absl::StrCat("joint \"", j.joint(), "\" has no driver"));
    }
  };
  auto spring = [&](const char* field, const v1::SpringOutput& sp, Q quantity) {
    const Where kw = ow.Child(field);
    out.quantity = quantity;
    auto it = multibody_springs_.find(sp.spring());
    if (it == multibody_springs_.end()) {
      errors_.Add(kw, "spring", absl::StrCat("unknown spring \"", sp.spring(), "\""));
    } else {
      out.spring = it->second;
    }
  };
  switch (o.kind_case()) {
    case v1::Output::kMarkerPosition: marker("marker_position", o.marker_position(), Q::kMarkerPosition); break;
    case v1::Output::kMarkerVelocity: marker("marker_velocity", o.marker_velocity(), Q::kMarkerVelocity); break;
    case v1::Output::kMarkerAcceleration: marker("marker_acceleration", o.marker_acceleration(), Q::kMarkerAcceleration); break;
    case v1::Output::kJointCoordinate: joint("joint_coordinate", o.joint_coordinate(), Q::kJointCoordinate, false); break;
    case v1::Output::kJointRate: joint("joint_rate", o.joint_rate(), Q::kJointRate, false); break;
    case v1::Output::kJointReaction: joint("joint_reaction", o.joint_reaction(), Q::kJointReaction, true); break;
    case v1::Output::kDriverEffort: joint("driver_effort", o.driver_effort(), Q::kDriverEffort, false); break;
    case v1::Output::kSpringLength: spring("spring_length", o.spring_length(), Q::kSpringLength); break;
    case v1::Output::kSpringForce: spring("spring_force", o.spring_force(), Q::kSpringForce); break;
    case v1::Output::kKineticEnergy: out.quantity = Q::kKineticEnergy; break;
    case v1::Output::kPotentialEnergy: out.quantity = Q::kPotentialEnergy; break;
    default: break;
  }
  const bool motion = out.quantity == Q::kMarkerVelocity || out.quantity == Q::kMarkerAcceleration ||
                      out.quantity == Q::kJointRate || out.quantity == Q::kKineticEnergy;
  if (motion && multibody_.analysis == MultibodyModel::Analysis::kStaticEquilibrium) {
    errors_.Add(ow, "",
                absl::StrCat("output \"", o.name(),
                             "\" is a rate, an acceleration or kinetic energy: a static-equilibrium analysis has "
                             "no motion (ask for positions, joint coordinates, reactions, driver efforts, spring "
                             "lengths and forces, potential energy)"));
  }
  return out;
}

}  // namespace mbopt::spec::io
