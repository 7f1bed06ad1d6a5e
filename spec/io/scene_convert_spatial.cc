// A `spatial` model: bodies with markers (frames), joints, drivers,
// spring-dampers and gravity, and the outputs read from it.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "spec/io/declared_name.h"
#include "spec/io/scene_converter.h"

namespace mbopt::spec::io {
namespace {

constexpr double kDegree = 3.14159265358979323846 / 180.0;

// The axes of a sequence (0 x, 1 y, 2 z), or false for an unknown value.
bool SequenceAxes(v1::EulerSequence sequence, int axes[3]) {
  static const std::map<v1::EulerSequence, std::array<int, 3>> table = {
      {v1::EULER_XYZ, {0, 1, 2}}, {v1::EULER_XZY, {0, 2, 1}}, {v1::EULER_YXZ, {1, 0, 2}},
      {v1::EULER_YZX, {1, 2, 0}}, {v1::EULER_ZXY, {2, 0, 1}}, {v1::EULER_ZYX, {2, 1, 0}},
      {v1::EULER_XYX, {0, 1, 0}}, {v1::EULER_XZX, {0, 2, 0}}, {v1::EULER_YXY, {1, 0, 1}},
      {v1::EULER_YZY, {1, 2, 1}}, {v1::EULER_ZXZ, {2, 0, 2}}, {v1::EULER_ZYZ, {2, 1, 2}}};
  auto it = table.find(sequence);
  if (it == table.end()) return false;
  std::copy(it->second.begin(), it->second.end(), axes);
  return true;
}

constexpr const char* kSequences =
    "EULER_XYZ, EULER_XZY, EULER_YXZ, EULER_YZX, EULER_ZXY, EULER_ZYX (Tait-Bryan) or EULER_XYX, EULER_XZX, "
    "EULER_YXY, EULER_YZY, EULER_ZXZ, EULER_ZYZ (proper Euler)";

Number Literal(double value) {
  Number n;
  n.value = value;
  return n;
}

}  // namespace

Vec3 SceneConverter::Vec3Of(const Where& w, const std::string& field, bool present, const v1::Vector3& v,
                            Dimension dimension) {
  Vec3 out;
  if (!present) return out;  // (0, 0, 0)
  const Where c = w.Child(field);
  out.x = Num(c, "x", v.has_x(), v.x(), dimension, 0.0);
  out.y = Num(c, "y", v.has_y(), v.y(), dimension, 0.0);
  out.z = Num(c, "z", v.has_z(), v.z(), dimension, 0.0);
  return out;
}

Orientation SceneConverter::OrientationOf(const Where& w, const std::string& field, bool present,
                                          const v1::Orientation& o) {
  Orientation out;
  if (!present) return out;
  const Where ow = w.Child(field);
  switch (o.form_case()) {
    case v1::Orientation::kAxisAngle: {
      const Where aw = ow.Child("axis_angle");
      const v1::AxisAngleRotation& a = o.axis_angle();
      out.form = Orientation::Form::kAxisAngle;
      const v1::Vector3& axis = a.axis();
      if (!a.has_axis() || (axis.has_x() && !axis.x().has_value()) || (axis.has_y() && !axis.y().has_value()) ||
          (axis.has_z() && !axis.z().has_value())) {
        errors_.Add(aw, "axis", "expected a literal non-zero axis `{ x { value: 0 } y { value: 0 } z { value: 1 } }`");
        break;
      }
      const double x = axis.x().value(), y = axis.y().value(), z = axis.z().value();
      const double norm = std::sqrt(x * x + y * y + z * z);
      if (!(norm > 0.0) || !std::isfinite(norm)) {
        errors_.Add(aw, "axis", absl::StrFormat("zero axis (%g, %g, %g): expected a non-zero vector", x, y, z));
        break;
      }
      out.axis[0] = x / norm;
      out.axis[1] = y / norm;
      out.axis[2] = z / norm;
      if (a.has_angle_rad() && a.angle_deg() != 0.0) {
        errors_.Add(aw, "angle_rad", "give angle_deg or angle_rad, not both");
      }
      if (a.has_angle_rad()) {
        out.angles_rad[0] = Num(aw, "angle_rad", true, a.angle_rad(), Dimension::kAngle);
      } else if (!std::isfinite(a.angle_deg())) {
        errors_.Add(aw, "angle_deg", "must be a finite number");
      } else {
        out.angles_rad[0] = Literal(a.angle_deg() * kDegree);
      }
      break;
    }
    case v1::Orientation::kEulerAngles: {
      const Where ew = ow.Child("euler_angles");
      const v1::EulerAngles& e = o.euler_angles();
      out.form = Orientation::Form::kEulerAngles;
      if (!SequenceAxes(e.sequence(), out.sequence)) {
        errors_.Add(ew, "sequence", absl::StrCat("missing or unknown: expected one of ", kSequences));
      }
      if (e.has_angles_rad() == (e.angles_deg_size() > 0)) {
        errors_.Add(ew, "angles_deg",
                    "expected the three angles once: `angles_deg: [30, 0, 45]` or `angles_rad { x { ... } y { ... } "
                    "z { ... } }`");
        break;
      }
      if (e.has_angles_rad()) {
        const Vec3 angles = Vec3Of(ew, "angles_rad", true, e.angles_rad(), Dimension::kAngle);
        out.angles_rad[0] = angles.x;
        out.angles_rad[1] = angles.y;
        out.angles_rad[2] = angles.z;
        break;
      }
      if (e.angles_deg_size() != 3) {
        errors_.Add(ew, "angles_deg", absl::StrFormat("expected three angles, got %d", e.angles_deg_size()));
        break;
      }
      for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(e.angles_deg(k))) errors_.Add(ew, "angles_deg", k, "must be a finite number");
        out.angles_rad[k] = Literal(e.angles_deg(k) * kDegree);
      }
      break;
    }
    case v1::Orientation::FORM_NOT_SET:
      errors_.Add(ow, "", "expected `axis_angle { ... }` or `euler_angles { ... }`");
      break;
  }
  return out;
}

std::vector<SpatialMarker> SceneConverter::SpatialMarkers(
    const Where& w, const std::string& field, const google::protobuf::RepeatedPtrField<v1::SpatialMarker>& markers) {
  std::vector<SpatialMarker> out;
  std::set<std::string> names;
  for (int k = 0; k < markers.size(); ++k) {
    const Where mw = w.Child(field, k);
    const v1::SpatialMarker& m = markers[k];
    SpatialMarker marker;
    marker.name = m.name();
    CheckDeclaredName(mw, m.name(), names.insert(m.name()).second,
                      {.missing = "a marker needs a name", .duplicate = "marker"}, &errors_);
    marker.position_m = Vec3Of(mw, "position_m", m.has_position_m(), m.position_m(), Dimension::kLength);
    marker.orientation = OrientationOf(mw, "orientation", m.has_orientation(), m.orientation());
    out.push_back(std::move(marker));
  }
  return out;
}

MarkerRef SceneConverter::SpatialMarkerOf(const Where& w, const std::string& field, const std::string& ref) {
  MarkerRef out;
  const size_t dot = ref.find('.');
  if (dot == std::string::npos) {
    errors_.Add(w, field, absl::StrCat("\"", ref, "\": expected \"body.marker\" or \"ground.marker\""));
    return out;
  }
  const std::string body = ref.substr(0, dot), marker = ref.substr(dot + 1);
  const std::vector<SpatialMarker>* markers = &spatial_.ground_markers;
  if (body != "ground") {
    auto it = spatial_bodies_.find(body);
    if (it == spatial_bodies_.end()) {
      errors_.Add(w, field, absl::StrCat("unknown body \"", body, "\" in \"", ref, "\" (bodies: ",
                                         spatial_bodies_.empty() ? "none" : absl::StrJoin(Names(spatial_bodies_), ", "),
                                         ")"));
      return out;
    }
    out.body = it->second;
    markers = &spatial_.bodies[static_cast<size_t>(out.body)].markers;
  }
  std::vector<std::string> names;
  for (size_t k = 0; k < markers->size(); ++k) {
    if ((*markers)[k].name == marker) out.marker = static_cast<int>(k);
    names.push_back((*markers)[k].name);
  }
  if (out.marker < 0) {
    errors_.Add(w, field, absl::StrCat("\"", body, "\" has no marker \"", marker, "\" (markers: ",
                                       names.empty() ? "none" : absl::StrJoin(names, ", "), ")"));
  }
  return out;
}

int SceneConverter::SpatialJointIndex(const Where& w, const std::string& field, const std::string& name) {
  auto it = spatial_joints_.find(name);
  if (it == spatial_joints_.end()) {
    errors_.Add(w, field, absl::StrCat("unknown joint \"", name, "\" (joints: ",
                                       spatial_joints_.empty() ? "none" : absl::StrJoin(Names(spatial_joints_), ", "),
                                       ")"));
    return -1;
  }
  return it->second;
}

SpatialModel SceneConverter::ConvertSpatial(const v1::SpatialModel& m, const Where& w) {
  spatial_ = SpatialModel{};
  switch (m.analysis()) {
    case v1::MULTIBODY_ANALYSIS_FROM_DEGREES_OF_FREEDOM: break;
    case v1::MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM:
      spatial_.analysis = MultibodyModel::Analysis::kStaticEquilibrium;
      break;
    default:
      errors_.Add(w, "analysis",
                  "expected MULTIBODY_ANALYSIS_FROM_DEGREES_OF_FREEDOM or MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM");
      break;
  }
  spatial_.ground_markers = SpatialMarkers(w, "ground_markers", m.ground_markers());
  for (int i = 0; i < m.bodies_size(); ++i) {
    const v1::SpatialBody& b = m.bodies(i);
    const Where bw = w.Child("bodies", i);
    SpatialBody body;
    body.name = b.name();
    CheckDeclaredName(bw, b.name(), spatial_bodies_.emplace(b.name(), i).second,
                      {.missing = "a body needs a name other than \"ground\"",
                       .duplicate = "body name",
                       .reserved = {"ground"}},
                      &errors_);
    body.mass_kg = Num(bw, "mass_kg", b.has_mass_kg(), b.mass_kg(), Dimension::kMass);
    RequirePositive(bw, "mass_kg", body.mass_kg);
    switch (b.inertia_case()) {
      case v1::SpatialBody::kPrincipalInertia: {
        const Where iw = bw.Child("principal_inertia");
        const v1::PrincipalInertia& pi = b.principal_inertia();
        if (!pi.has_moments_kg_m2()) {
          errors_.Add(iw, "moments_kg_m2", "missing: expected the three principal moments about the centre of mass");
        }
        body.principal_moments_kg_m2 =
            Vec3Of(iw, "moments_kg_m2", pi.has_moments_kg_m2(), pi.moments_kg_m2(), Dimension::kInertia);
        const Where mw = iw.Child("moments_kg_m2");
        RequirePositive(mw, "x", body.principal_moments_kg_m2.x);
        RequirePositive(mw, "y", body.principal_moments_kg_m2.y);
        RequirePositive(mw, "z", body.principal_moments_kg_m2.z);
        body.principal_axes = OrientationOf(iw, "axes", pi.has_axes(), pi.axes());
        break;
      }
      case v1::SpatialBody::kInertiaComponents: {
        const Where iw = bw.Child("inertia_components");
        const v1::InertiaComponents& c = b.inertia_components();
        body.components = true;
        body.inertia_components_kg_m2[0] = Num(iw, "ixx_kg_m2", c.has_ixx_kg_m2(), c.ixx_kg_m2(), Dimension::kInertia);
        body.inertia_components_kg_m2[1] = Num(iw, "iyy_kg_m2", c.has_iyy_kg_m2(), c.iyy_kg_m2(), Dimension::kInertia);
        body.inertia_components_kg_m2[2] = Num(iw, "izz_kg_m2", c.has_izz_kg_m2(), c.izz_kg_m2(), Dimension::kInertia);
        body.inertia_components_kg_m2[3] =
            Num(iw, "ixy_kg_m2", c.has_ixy_kg_m2(), c.ixy_kg_m2(), Dimension::kInertia, 0.0);
        body.inertia_components_kg_m2[4] =
            Num(iw, "ixz_kg_m2", c.has_ixz_kg_m2(), c.ixz_kg_m2(), Dimension::kInertia, 0.0);
        body.inertia_components_kg_m2[5] =
            Num(iw, "iyz_kg_m2", c.has_iyz_kg_m2(), c.iyz_kg_m2(), Dimension::kInertia, 0.0);
        RequirePositive(iw, "ixx_kg_m2", body.inertia_components_kg_m2[0]);
        RequirePositive(iw, "iyy_kg_m2", body.inertia_components_kg_m2[1]);
        RequirePositive(iw, "izz_kg_m2", body.inertia_components_kg_m2[2]);
        break;
      }
      case v1::SpatialBody::INERTIA_NOT_SET:
        errors_.Add(bw, "",
                    "missing inertia: expected `principal_inertia { moments_kg_m2 { ... } }` or "
                    "`inertia_components { ixx_kg_m2 { ... } ... }`");
        break;
    }
    body.position_m = Vec3Of(bw, "position_m", b.has_position_m(), b.position_m(), Dimension::kLength);
    body.orientation = OrientationOf(bw, "orientation", b.has_orientation(), b.orientation());
    body.velocity_m_per_s =
        Vec3Of(bw, "velocity_m_per_s", b.has_velocity_m_per_s(), b.velocity_m_per_s(), Dimension::kVelocity);
    body.angular_velocity_rad_per_s = Vec3Of(bw, "angular_velocity_rad_per_s", b.has_angular_velocity_rad_per_s(),
                                             b.angular_velocity_rad_per_s(), Dimension::kAngularVelocity);
    body.markers = SpatialMarkers(bw, "markers", b.markers());
    spatial_.bodies.push_back(std::move(body));
  }
  if (m.bodies_size() == 0) errors_.Add(w, "bodies", "a spatial model needs at least one body");
  for (int i = 0; i < m.joints_size(); ++i) {
    const v1::SpatialJoint& j = m.joints(i);
    const Where jw = w.Child("joints", i);
    SpatialJoint joint;
    joint.name = j.name();
    CheckDeclaredName(jw, j.name(), spatial_joints_.emplace(j.name(), i).second,
                      {.missing = "a joint needs a name", .duplicate = "joint name"}, &errors_);
    using K = SpatialJointKind;
    switch (j.kind()) {
      case v1::SPATIAL_JOINT_SPHERICAL: joint.kind = K::kSpherical; break;
      case v1::SPATIAL_JOINT_REVOLUTE: joint.kind = K::kRevolute; break;
      case v1::SPATIAL_JOINT_UNIVERSAL: joint.kind = K::kUniversal; break;
      case v1::SPATIAL_JOINT_FIXED: joint.kind = K::kFixed; break;
      case v1::SPATIAL_JOINT_PRISMATIC: joint.kind = K::kPrismatic; break;
      case v1::SPATIAL_JOINT_CYLINDRICAL: joint.kind = K::kCylindrical; break;
      case v1::SPATIAL_JOINT_PLANAR: joint.kind = K::kPlanar; break;
      case v1::SPATIAL_JOINT_POINT_ON_LINE: joint.kind = K::kPointOnLine; break;
      case v1::SPATIAL_JOINT_POINT_ON_PLANE: joint.kind = K::kPointOnPlane; break;
      default:
        errors_.Add(jw, "kind",
                    "expected SPATIAL_JOINT_SPHERICAL, _REVOLUTE, _UNIVERSAL, _FIXED, _PRISMATIC, _CYLINDRICAL, "
                    "_PLANAR, _POINT_ON_LINE or _POINT_ON_PLANE");
    }
    joint.a = SpatialMarkerOf(jw, "a", j.a());
    joint.b = SpatialMarkerOf(jw, "b", j.b());
    if (joint.a.marker >= 0 && joint.b.marker >= 0 && joint.a.body == joint.b.body) {
      errors_.Add(jw, "b", "a joint joins two different bodies (or a body and ground)");
    }
    spatial_.joints.push_back(std::move(joint));
  }
  std::set<std::pair<int, bool>> driven;  // (joint, slide)
  for (int i = 0; i < m.drivers_size(); ++i) {
    const v1::SpatialDriver& d = m.drivers(i);
    const Where dw = w.Child("drivers", i);
    MultibodyDriver driver;
    driver.joint = SpatialJointIndex(dw, "joint", d.joint());
    driver.slide = d.slide();
    if (driver.joint >= 0) {
      const SpatialJointKind kind = spatial_.joints[static_cast<size_t>(driver.joint)].kind;
      if (kind == SpatialJointKind::kPrismatic) driver.slide = true;
      if (kind == SpatialJointKind::kRevolute && d.slide()) {
        errors_.Add(dw, "slide", absl::StrCat("joint \"", d.joint(),
                                              "\" is revolute: it has no slide (drive a prismatic or cylindrical one)"));
      } else if (kind != SpatialJointKind::kRevolute && kind != SpatialJointKind::kCylindrical &&
                 kind != SpatialJointKind::kPrismatic) {
        errors_.Add(dw, "joint",
                    absl::StrCat("joint \"", d.joint(),
                                 "\" is not revolute, prismatic or cylindrical: a spatial driver prescribes the angle "
                                 "of a revolute or cylindrical joint or the slide (`slide: true`) of a prismatic or "
                                 "cylindrical one"));
      }
      if (!driven.insert({driver.joint, driver.slide}).second) {
        errors_.Add(dw, "joint", driver.slide ? "this joint's slide already has a driver"
                                              : "this joint's angle already has a driver");
      }
    }
    // The profile's values are the coordinate's: m for a slide, rad for an angle.
    const Dimension coordinate = driver.slide ? Dimension::kLength : Dimension::kAngle;
    const Dimension rate = driver.slide ? Dimension::kVelocity : Dimension::kAngularVelocity;
    switch (d.profile_case()) {
      case v1::SpatialDriver::kConstantRate: {
        const Where pw = dw.Child("constant_rate");
        driver.profile = MultibodyDriver::Profile::kConstantRate;
        driver.start = Num(pw, "start", d.constant_rate().has_start(), d.constant_rate().start(), coordinate, 0.0);
        driver.rate = Num(pw, "rate", d.constant_rate().has_rate(), d.constant_rate().rate(), rate);
        break;
      }
      case v1::SpatialDriver::kPolynomial: {
        const Where pw = dw.Child("polynomial");
        driver.profile = MultibodyDriver::Profile::kPolynomial;
        for (int k = 0; k < d.polynomial().coefficients_size(); ++k) {
          driver.coefficients.push_back(
              Num(pw, absl::StrCat("coefficients[", k, "]"), true, d.polynomial().coefficients(k), Dimension::kAny));
        }
        if (driver.coefficients.empty()) errors_.Add(pw, "coefficients", "a polynomial needs at least one coefficient");
        break;
      }
      case v1::SpatialDriver::kHarmonic: Harmonic(dw.Child("harmonic"), d.harmonic(), &driver); break;
      case v1::SpatialDriver::kTabulated: Tabulated(dw.Child("tabulated"), d.tabulated(), &driver); break;
      case v1::SpatialDriver::PROFILE_NOT_SET:
        errors_.Add(dw, "", "a driver needs a profile: `constant_rate`, `polynomial`, `harmonic` or `tabulated`");
        break;
    }
    spatial_.drivers.push_back(std::move(driver));
  }
  for (int i = 0; i < m.springs_size(); ++i) {
    const v1::SpatialSpring& sp = m.springs(i);
    const Where sw = w.Child("springs", i);
    SpatialSpring spring;
    spring.name = sp.name();
    CheckDeclaredName(sw, sp.name(), spatial_springs_.emplace(sp.name(), i).second,
                      {.missing = "a spring needs a name", .duplicate = "spring name"}, &errors_);
    spring.a = SpatialMarkerOf(sw, "a", sp.a());
    spring.b = SpatialMarkerOf(sw, "b", sp.b());
    if (spring.a.marker >= 0 && spring.b.marker >= 0 && spring.a.body == spring.b.body) {
      errors_.Add(sw, "b", "a spring joins two different bodies (or a body and ground)");
    }
    spring.free_length_m =
        Num(sw, "free_length_m", sp.has_free_length_m(), sp.free_length_m(), Dimension::kLength, 0.0);
    RequireNotNegative(sw, "free_length_m", spring.free_length_m);
    spring.stiffness_n_per_m = Num(sw, "stiffness_n_per_m", sp.has_stiffness_n_per_m(), sp.stiffness_n_per_m(),
                                   Dimension::kStiffness, 0.0);
    RequireNotNegative(sw, "stiffness_n_per_m", spring.stiffness_n_per_m);
    spring.damping_n_s_per_m = Num(sw, "damping_n_s_per_m", sp.has_damping_n_s_per_m(), sp.damping_n_s_per_m(),
                                   Dimension::kDamping, 0.0);
    RequireNotNegative(sw, "damping_n_s_per_m", spring.damping_n_s_per_m);
    spatial_.springs.push_back(std::move(spring));
  }
  if (m.has_gravity()) {
    const Where gw = w.Child("gravity");
    if (!m.gravity().has_acceleration_m_per_s2()) {
      errors_.Add(gw, "acceleration_m_per_s2", "missing: expected e.g. `{ z { value: -9.81 } }`");
    }
    spatial_.gravity_m_per_s2 = Vec3Of(gw, "acceleration_m_per_s2", m.gravity().has_acceleration_m_per_s2(),
                                       m.gravity().acceleration_m_per_s2(), Dimension::kAcceleration);
  }
  ConvertSpatialForces(m, w);
  return spatial_;
}

SpatialOutput SceneConverter::SpatialOutputOf(const v1::Output& o, const Where& ow) {
  using Q = SpatialOutput::Quantity;
  const SpatialOutput out = SpatialQuantityOf(o, ow);
  const bool motion = out.quantity == Q::kMarkerVelocity || out.quantity == Q::kMarkerAcceleration ||
                      out.quantity == Q::kJointRate || out.quantity == Q::kJointSlideRate ||
                      out.quantity == Q::kBodyAngularVelocity || out.quantity == Q::kKineticEnergy;
  if (motion && spatial_.analysis == MultibodyModel::Analysis::kStaticEquilibrium) {
    errors_.Add(ow, "",
                absl::StrCat("output \"", o.name(),
                             "\" is a rate, an acceleration or kinetic energy: a static-equilibrium analysis has "
                             "no motion (ask for positions, orientations, joint coordinates, reactions, driver "
                             "efforts, spring, rotational spring and bushing forces, potential energy)"));
  }
  return out;
}

SpatialOutput SceneConverter::SpatialQuantityOf(const v1::Output& o, const Where& ow) {
  using Q = SpatialOutput::Quantity;
  SpatialOutput out;
  if (SpatialForceOutputOf(o, ow, &out)) return out;
  auto axis_of = [&](const Where& kw, v1::Axis axis) {
    switch (axis) {
      case v1::AXIS_X: return Axis::kX;
      case v1::AXIS_Y: return Axis::kY;
      case v1::AXIS_Z: return Axis::kZ;
      default: errors_.Add(kw, "axis", "expected AXIS_X, AXIS_Y or AXIS_Z (world axes)"); return Axis::kX;
    }
  };
  auto marker = [&](const char* field, const v1::MarkerOutput& m, Q quantity) {
    const Where kw = ow.Child(field);
    out.quantity = quantity;
    out.marker = SpatialMarkerOf(kw, "marker", m.marker());
    out.axis = axis_of(kw, m.axis());
  };
  auto joint = [&](const char* field, const v1::JointOutput& j, Q quantity) {
    const Where kw = ow.Child(field);
    out.quantity = quantity;
    out.joint = SpatialJointIndex(kw, "joint", j.joint());
    if (out.joint < 0) return;
    const SpatialJointKind kind = spatial_.joints[static_cast<size_t>(out.joint)].kind;
    const bool slide = quantity == Q::kJointSlide || quantity == Q::kJointSlideRate;
    const bool ok = slide ? kind == SpatialJointKind::kPrismatic || kind == SpatialJointKind::kCylindrical
                          : kind == SpatialJointKind::kRevolute || kind == SpatialJointKind::kCylindrical ||
                                kind == SpatialJointKind::kPrismatic;
    if (!ok) {
      errors_.Add(kw, "joint",
                  absl::StrCat("joint \"", j.joint(), "\" has no ", slide ? "slide" : "coordinate",
                               slide ? ": expected a prismatic or cylindrical joint"
                                     : ": expected a revolute, cylindrical (its angle) or prismatic (its slide) joint"));
    }
    out.linear = slide || kind == SpatialJointKind::kPrismatic;
  };
  auto spring = [&](const char* field, const v1::SpringOutput& sp, Q quantity) {
    const Where kw = ow.Child(field);
    out.quantity = quantity;
    auto it = spatial_springs_.find(sp.spring());
    if (it == spatial_springs_.end()) {
      errors_.Add(kw, "spring", absl::StrCat("unknown spring \"", sp.spring(), "\""));
    } else {
      out.spring = it->second;
    }
  };
  switch (o.kind_case()) {
    case v1::Output::kMarkerPosition: marker("marker_position", o.marker_position(), Q::kMarkerPosition); break;
    case v1::Output::kMarkerVelocity: marker("marker_velocity", o.marker_velocity(), Q::kMarkerVelocity); break;
    case v1::Output::kMarkerAcceleration:
      marker("marker_acceleration", o.marker_acceleration(), Q::kMarkerAcceleration);
      break;
    case v1::Output::kJointCoordinate: joint("joint_coordinate", o.joint_coordinate(), Q::kJointCoordinate); break;
    case v1::Output::kJointRate: joint("joint_rate", o.joint_rate(), Q::kJointRate); break;
    case v1::Output::kJointSlide: joint("joint_slide", o.joint_slide(), Q::kJointSlide); break;
    case v1::Output::kJointSlideRate: joint("joint_slide_rate", o.joint_slide_rate(), Q::kJointSlideRate); break;
    case v1::Output::kSpringLength: spring("spring_length", o.spring_length(), Q::kSpringLength); break;
    case v1::Output::kSpringForce: spring("spring_force", o.spring_force(), Q::kSpringForce); break;
    case v1::Output::kDriverEffort: {
      // The angle's driver when the joint has one, else the slide's.
      const Where kw = ow.Child("driver_effort");
      out.quantity = Q::kDriverEffort;
      out.joint = SpatialJointIndex(kw, "joint", o.driver_effort().joint());
      for (size_t d = 0; d < spatial_.drivers.size() && out.joint >= 0; ++d) {
        const MultibodyDriver& driver = spatial_.drivers[d];
        if (driver.joint == out.joint && (out.driver < 0 || !driver.slide)) {
          out.driver = static_cast<int>(d);
          out.linear = driver.slide;
        }
      }
      if (out.joint >= 0 && out.driver < 0) {
        errors_.Add(kw, "joint", absl::StrCat("joint \"", o.driver_effort().joint(),
                                              "\" has no driver: a driver effort needs one"));
      }
      break;
    }
    case v1::Output::kKineticEnergy: out.quantity = Q::kKineticEnergy; break;
    case v1::Output::kPotentialEnergy: out.quantity = Q::kPotentialEnergy; break;
    case v1::Output::kBodyOrientation: {
      const Where kw = ow.Child("body_orientation");
      const v1::BodyOrientationOutput& b = o.body_orientation();
      out.quantity = Q::kBodyOrientation;
      auto it = spatial_bodies_.find(b.body());
      if (it == spatial_bodies_.end()) {
        errors_.Add(kw, "body", absl::StrCat("unknown body \"", b.body(), "\" (bodies: ",
                                             absl::StrJoin(Names(spatial_bodies_), ", "), ")"));
      } else {
        out.body = it->second;
      }
      if (!SequenceAxes(b.sequence(), out.sequence)) {
        errors_.Add(kw, "sequence", absl::StrCat("missing or unknown: expected one of ", kSequences));
      }
      if (b.angle() < 1 || b.angle() > 3) {
        errors_.Add(kw, "angle", absl::StrFormat("expected 1, 2 or 3 (which angle of the sequence), got %d", b.angle()));
      }
      out.angle = std::clamp(b.angle() - 1, 0, 2);
      break;
    }
    default: break;
  }
  return out;
}

}  // namespace mbopt::spec::io
