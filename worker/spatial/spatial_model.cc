#include "worker/spatial/spatial_model.h"

#include <cmath>

#include "absl/strings/str_format.h"
#include "worker/spatial/spatial_force_elements.h"

namespace mbopt::spatial {
namespace {

// Orthonormality of a rotation given by the user to this many digits: the
// engine does not re-orthogonalize, and an axis off by 1e-9 rad is far
// below any tolerance an analysis is asked for.
constexpr double kRotationTolerance = 1e-9;

bool IsRotation(const Eigen::Matrix3d& r) {
  return r.allFinite() && (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < kRotationTolerance &&
         std::abs(r.determinant() - 1.0) < kRotationTolerance;
}

std::string Describe(const Eigen::Matrix3d& m) {
  return absl::StrFormat("[[%.6g %.6g %.6g] [%.6g %.6g %.6g] [%.6g %.6g %.6g]]", m(0, 0), m(0, 1), m(0, 2), m(1, 0),
                         m(1, 1), m(1, 2), m(2, 0), m(2, 1), m(2, 2));
}

absl::Status CheckBodyIndex(const Model& m, int body, const std::string& where) {
  if (body < kGround || body >= static_cast<int>(m.bodies.size())) {
    return absl::InvalidArgumentError(absl::StrFormat("%s: body index %d is not ground (-1) or one of the %d bodies",
                                                      where, body, m.bodies.size()));
  }
  return absl::OkStatus();
}

absl::Status CheckFrame(const Model& m, const Frame& f, const std::string& where) {
  if (absl::Status s = CheckBodyIndex(m, f.body, where); !s.ok()) return s;
  if (!f.position_m.allFinite()) return absl::InvalidArgumentError(where + ": position is not finite");
  if (!IsRotation(f.axes)) {
    return absl::InvalidArgumentError(where + ": axes " + Describe(f.axes) +
                                      " are not a rotation (orthonormal columns, determinant +1)");
  }
  return absl::OkStatus();
}

}  // namespace

const char* JointKindName(Joint::Kind kind) {
  switch (kind) {
    case Joint::Kind::kSpherical: return "spherical";
    case Joint::Kind::kRevolute: return "revolute";
    case Joint::Kind::kUniversal: return "universal";
    case Joint::Kind::kFixed: return "fixed";
    case Joint::Kind::kPrismatic: return "prismatic";
    case Joint::Kind::kCylindrical: return "cylindrical";
    case Joint::Kind::kPlanar: return "planar";
    case Joint::Kind::kPointOnLine: return "point on line";
    case Joint::Kind::kPointOnPlane: return "point on plane";
  }
  return "unknown";
}

int JointEquationCount(Joint::Kind kind) {
  switch (kind) {
    case Joint::Kind::kSpherical: return 3;
    case Joint::Kind::kRevolute: return 5;
    case Joint::Kind::kUniversal: return 4;
    case Joint::Kind::kFixed: return 6;
    case Joint::Kind::kPrismatic: return 5;
    case Joint::Kind::kCylindrical: return 4;
    case Joint::Kind::kPlanar: return 3;
    case Joint::Kind::kPointOnLine: return 2;
    case Joint::Kind::kPointOnPlane: return 1;
  }
  return 0;
}

std::string Model::BodyName(int body) const {
  if (body == kGround) return "ground";
  if (body < 0 || body >= static_cast<int>(bodies.size())) return absl::StrFormat("body #%d", body);
  return "body '" + bodies[static_cast<size_t>(body)].name + "'";
}

absl::Status Model::Validate() const {
  for (size_t i = 0; i < bodies.size(); ++i) {
    const Body& b = bodies[i];
    const std::string where = "body '" + b.name + "'";
    if (!(b.mass_kg > 0.0) || !std::isfinite(b.mass_kg)) {
      return absl::InvalidArgumentError(absl::StrFormat("%s: mass %g kg, expected a positive finite number", where,
                                                        b.mass_kg));
    }
    const Eigen::Matrix3d& j = b.inertia_kg_m2;
    if (!j.allFinite() || (j - j.transpose()).cwiseAbs().maxCoeff() > 1e-12 * j.cwiseAbs().maxCoeff()) {
      return absl::InvalidArgumentError(where + ": inertia tensor " + Describe(j) + " is not symmetric");
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> principal(j);
    const Eigen::Vector3d moments = principal.eigenvalues();  // ascending
    if (!(moments[0] > 0.0)) {
      return absl::InvalidArgumentError(where + ": inertia tensor " + Describe(j) +
                                        " is not positive definite (principal moments " +
                                        absl::StrFormat("%g, %g, %g kg m^2)", moments[0], moments[1], moments[2]));
    }
    // A real mass distribution has J3 <= J1 + J2 (with equality only for a
    // flat body): a tensor outside it is a typing error.
    if (moments[2] > (moments[0] + moments[1]) * (1.0 + 1e-9)) {
      return absl::InvalidArgumentError(
          absl::StrFormat("%s: principal moments %g, %g, %g kg m^2 violate the triangle inequality (the largest must "
                          "not exceed the sum of the other two)",
                          where, moments[0], moments[1], moments[2]));
    }
    if (!b.position_m.allFinite() || !b.velocity_m_per_s.allFinite() || !b.angular_velocity_rad_per_s.allFinite()) {
      return absl::InvalidArgumentError(where + ": initial position or velocity is not finite");
    }
    if (!IsRotation(b.orientation)) {
      return absl::InvalidArgumentError(where + ": orientation " + Describe(b.orientation) +
                                        " is not a rotation (orthonormal columns, determinant +1)");
    }
  }
  for (const Joint& joint : joints) {
    const std::string where = std::string(JointKindName(joint.kind)) + " joint '" + joint.name + "'";
    if (absl::Status s = CheckFrame(*this, joint.a, where + ", frame a"); !s.ok()) return s;
    if (absl::Status s = CheckFrame(*this, joint.b, where + ", frame b"); !s.ok()) return s;
    if (joint.a.body == joint.b.body) {
      return absl::InvalidArgumentError(where + ": both frames are on " + BodyName(joint.a.body) +
                                        ", expected two different bodies");
    }
  }
  for (size_t i = 0; i < drivers.size(); ++i) {
    const Driver& d = drivers[i];
    const std::string where = absl::StrFormat("driver %d", i);
    if (d.joint < 0 || d.joint >= static_cast<int>(joints.size())) {
      return absl::InvalidArgumentError(absl::StrFormat("%s: joint index %d is not one of the %d joints", where,
                                                        d.joint, joints.size()));
    }
    const Joint& joint = joints[static_cast<size_t>(d.joint)];
    const bool rotates = joint.kind == Joint::Kind::kRevolute || joint.kind == Joint::Kind::kCylindrical;
    const bool slides = joint.kind == Joint::Kind::kPrismatic || joint.kind == Joint::Kind::kCylindrical;
    if (d.slide ? !slides : !rotates) {
      return absl::InvalidArgumentError(where + ": drives the " + (d.slide ? "slide" : "rotation") + " of " +
                                        JointKindName(joint.kind) + " joint '" + joint.name + "', expected " +
                                        (d.slide ? "a prismatic or cylindrical joint" : "a revolute or cylindrical joint"));
    }
    if (d.profile.kind == multibody::Profile::Kind::kTabulated && d.profile.table.empty()) {
      return absl::InvalidArgumentError(where + ": tabulated profile without a table");
    }
    for (size_t k = 0; k < i; ++k) {
      if (drivers[k].joint == d.joint && drivers[k].slide == d.slide) {
        return absl::InvalidArgumentError(where + ": joint '" + joint.name + "' is already driven by driver " +
                                          std::to_string(k));
      }
    }
  }
  for (const SpringDamper& s : springs) {
    const std::string where = "spring-damper '" + s.name + "'";
    if (absl::Status st = CheckBodyIndex(*this, s.a.body, where + ", point a"); !st.ok()) return st;
    if (absl::Status st = CheckBodyIndex(*this, s.b.body, where + ", point b"); !st.ok()) return st;
    if (s.a.body == s.b.body) {
      return absl::InvalidArgumentError(where + ": both points are on " + BodyName(s.a.body));
    }
    if (!(s.stiffness_n_per_m >= 0.0) || !(s.damping_n_s_per_m >= 0.0) || !(s.free_length_m >= 0.0) ||
        !std::isfinite(s.stiffness_n_per_m + s.damping_n_s_per_m + s.free_length_m) || !s.a.position_m.allFinite() ||
        !s.b.position_m.allFinite()) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "%s: stiffness %g N/m, damping %g N s/m, free length %g m: expected finite values >= 0", where,
          s.stiffness_n_per_m, s.damping_n_s_per_m, s.free_length_m));
    }
  }
  if (gravity_m_per_s2 && !gravity_m_per_s2->allFinite()) {
    return absl::InvalidArgumentError("gravity is not finite");
  }
  return ValidateForceElements(*this);
}

}  // namespace mbopt::spatial
