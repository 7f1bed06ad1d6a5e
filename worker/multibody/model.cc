#include "worker/multibody/model.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace mbopt::multibody {

Profile::Value Profile::At(double t) const {
  Value v;
  switch (kind) {
    case Kind::kConstantRate:
      v.q = start + rate * t;
      v.q_dot = rate;
      break;
    case Kind::kPolynomial: {
      // Horner's scheme for q, q' and q'' together.
      for (size_t k = coefficients.size(); k-- > 0;) {
        v.q_ddot = v.q_ddot * t + 2.0 * v.q_dot;
        v.q_dot = v.q_dot * t + v.q;
        v.q = v.q * t + coefficients[k];
      }
      break;
    }
    case Kind::kHarmonic: {
      const double w = angular_frequency_rad_per_s;
      const double s = std::sin(w * t + phase_rad), c = std::cos(w * t + phase_rad);
      v.q = start + amplitude * s;
      v.q_dot = amplitude * w * c;
      v.q_ddot = -amplitude * w * w * s;
      break;
    }
  }
  return v;
}

std::string Model::BodyName(int body) const {
  if (body == kGround) return "ground";
  if (body >= 0 && static_cast<size_t>(body) < bodies.size()) return bodies[static_cast<size_t>(body)].name;
  return absl::StrCat("body #", body);
}

namespace {

bool Finite(const Eigen::Vector2d& v) { return std::isfinite(v.x()) && std::isfinite(v.y()); }

absl::Status CheckPoint(const Model& m, const Point& p, const std::string& where) {
  if (p.body != kGround && (p.body < 0 || static_cast<size_t>(p.body) >= m.bodies.size())) {
    return absl::InvalidArgumentError(absl::StrCat(where, ": unknown body #", p.body));
  }
  if (!Finite(p.local_m)) return absl::InvalidArgumentError(absl::StrCat(where, ": point is not finite"));
  return absl::OkStatus();
}

}  // namespace

absl::Status Model::Validate() const {
  if (bodies.empty()) return absl::InvalidArgumentError("a multibody model needs at least one body");
  for (const Body& b : bodies) {
    if (!(b.mass_kg > 0.0) || !std::isfinite(b.mass_kg)) {
      return absl::InvalidArgumentError(absl::StrCat("body ", b.name, ": mass must be > 0 kg, got ", b.mass_kg));
    }
    if (!(b.inertia_kg_m2 > 0.0) || !std::isfinite(b.inertia_kg_m2)) {
      return absl::InvalidArgumentError(
          absl::StrCat("body ", b.name, ": inertia must be > 0 kg m^2, got ", b.inertia_kg_m2));
    }
    if (!Finite(b.position_m) || !std::isfinite(b.angle_rad)) {
      return absl::InvalidArgumentError(absl::StrCat("body ", b.name, ": initial pose is not finite"));
    }
  }
  for (const Joint& j : joints) {
    if (absl::Status s = CheckPoint(*this, j.a, "joint " + j.name); !s.ok()) return s;
    if (absl::Status s = CheckPoint(*this, j.b, "joint " + j.name); !s.ok()) return s;
    if (j.a.body == j.b.body) {
      return absl::InvalidArgumentError(absl::StrCat("joint ", j.name, " joins ", BodyName(j.a.body), " to itself"));
    }
  }
  std::vector<int> driven(joints.size(), 0);
  for (const Driver& d : drivers) {
    if (d.joint < 0 || static_cast<size_t>(d.joint) >= joints.size()) {
      return absl::InvalidArgumentError(absl::StrCat("driver on unknown joint #", d.joint));
    }
    const Joint& j = joints[static_cast<size_t>(d.joint)];
    if (j.kind == JointKind::kFixed) {
      return absl::InvalidArgumentError(absl::StrCat("driver on joint ", j.name, ": a fixed joint cannot be driven"));
    }
    if (++driven[static_cast<size_t>(d.joint)] > 1) {
      return absl::InvalidArgumentError(absl::StrCat("joint ", j.name, " has more than one driver"));
    }
  }
  for (const SpringDamper& s : springs) {
    if (absl::Status st = CheckPoint(*this, s.a, "spring " + s.name); !st.ok()) return st;
    if (absl::Status st = CheckPoint(*this, s.b, "spring " + s.name); !st.ok()) return st;
    if (!(s.free_length_m >= 0.0) || !std::isfinite(s.stiffness_n_per_m) || !std::isfinite(s.damping_n_s_per_m) ||
        !std::isfinite(s.actuator_force_n)) {
      return absl::InvalidArgumentError(absl::StrCat("spring ", s.name, ": free length must be >= 0 m and every "
                                                     "coefficient finite"));
    }
  }
  for (const RotationalSpringDamper& r : rotational_springs) {
    if (r.joint < 0 || static_cast<size_t>(r.joint) >= joints.size() ||
        joints[static_cast<size_t>(r.joint)].kind != JointKind::kRevolute) {
      return absl::InvalidArgumentError(absl::StrCat("rotational spring ", r.name, " must act at a revolute joint"));
    }
  }
  for (const PointForce& f : point_forces) {
    if (absl::Status st = CheckPoint(*this, f.at, "point force"); !st.ok()) return st;
  }
  for (const BodyTorque& t : torques) {
    if (t.body < 0 || static_cast<size_t>(t.body) >= bodies.size()) {
      return absl::InvalidArgumentError(absl::StrCat("torque on unknown body #", t.body));
    }
  }
  return absl::OkStatus();
}

}  // namespace mbopt::multibody
