#include "worker/multibody/model.h"

#include <algorithm>
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
    case Kind::kTabulated:
      // Outside the table (excluded when the scene is loaded): NaN, which the
      // engine reports as a failed analysis.
      if (!table.Evaluate(t, &v.q, &v.q_dot, &v.q_ddot)) v.q = v.q_dot = v.q_ddot = NAN;
      break;
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

CubicSpline::CubicSpline(std::vector<double> x, std::vector<double> y) : x_(std::move(x)), y_(std::move(y)) {
  const size_t n = x_.size();
  second_.assign(n, 0.0);
  if (n < 3) return;
  // Natural spline: second derivatives zero at the ends; the tridiagonal
  // system by the Thomas algorithm.
  std::vector<double> c(n, 0.0), d(n, 0.0);
  for (size_t i = 1; i + 1 < n; ++i) {
    const double h0 = x_[i] - x_[i - 1], h1 = x_[i + 1] - x_[i];
    const double a = h0, b = 2.0 * (h0 + h1), cc = h1;
    const double r = 6.0 * ((y_[i + 1] - y_[i]) / h1 - (y_[i] - y_[i - 1]) / h0);
    const double m = b - a * c[i - 1];
    c[i] = cc / m;
    d[i] = (r - a * d[i - 1]) / m;
  }
  for (size_t i = n - 2; i >= 1; --i) {
    second_[i] = d[i] - c[i] * second_[i + 1];
    if (i == 1) break;
  }
}

bool CubicSpline::Evaluate(double x, double* y, double* dy, double* d2y) const {
  if (x_.size() < 2 || !(x >= x_.front() && x <= x_.back())) return false;
  const size_t k = std::min<size_t>(
      static_cast<size_t>(std::upper_bound(x_.begin(), x_.end(), x) - x_.begin()), x_.size() - 1);
  const size_t i = k == 0 ? 0 : k - 1;
  const double h = x_[i + 1] - x_[i];
  const double a = (x_[i + 1] - x) / h, b = (x - x_[i]) / h;
  const double m0 = second_[i], m1 = second_[i + 1];
  *y = a * y_[i] + b * y_[i + 1] + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
  *dy = (y_[i + 1] - y_[i]) / h + ((1.0 - 3.0 * a * a) * m0 + (3.0 * b * b - 1.0) * m1) * h / 6.0;
  *d2y = a * m0 + b * m1;
  return true;
}

bool LinearTable::Evaluate(double at, double* value) const {
  if (x.size() < 2 || !(at >= x.front() && at <= x.back())) return false;
  const size_t k = std::min<size_t>(static_cast<size_t>(std::upper_bound(x.begin(), x.end(), at) - x.begin()),
                                    x.size() - 1);
  const size_t i = k == 0 ? 0 : k - 1;
  const double w = (at - x[i]) / (x[i + 1] - x[i]);
  *value = (1.0 - w) * y[i] + w * y[i + 1];
  return true;
}

double LinearTable::Continued(double at) const {
  double value = 0.0;
  if (Evaluate(at, &value)) return value;
  const size_t i = at < x.front() ? 0 : x.size() - 2;
  return y[i] + (y[i + 1] - y[i]) / (x[i + 1] - x[i]) * (at - x[i]);
}

double LinearTable::Slope(double at) const {
  if (x.size() < 2) return 0.0;
  const size_t k = std::min<size_t>(static_cast<size_t>(std::upper_bound(x.begin(), x.end(), at) - x.begin()),
                                    x.size() - 1);
  const size_t i = k == 0 ? 0 : k - 1;
  return (y[i + 1] - y[i]) / (x[i + 1] - x[i]);
}

std::string Model::BodyName(int body) const {
  if (body == kGround) return "ground";
  if (body >= 0 && static_cast<size_t>(body) < bodies.size()) return bodies[static_cast<size_t>(body)].name;
  return absl::StrCat("body #", body);
}

namespace {

bool Finite(const Eigen::Vector2d& v) { return std::isfinite(v.x()) && std::isfinite(v.y()); }

absl::Status CheckPoint(const Model& m, const Point& p, const std::string& where) {
  if (p.input >= 0 && (p.body != kGround || static_cast<size_t>(p.input) >= m.inputs.size())) {
    return absl::InvalidArgumentError(absl::StrCat(where, ": unknown input point #", p.input));
  }
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
    if (j.a.input >= 0 || j.b.input >= 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("joint ", j.name, ": a moving input point takes springs and forces, not joints"));
    }
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
  for (const SpringDamper& s : springs) {
    for (const LinearTable* table : {&s.deflection_curve, &s.velocity_curve}) {
      if (table->empty()) continue;
      bool increasing = table->x.size() >= 2 && table->x.size() == table->y.size();
      for (size_t k = 1; increasing && k < table->x.size(); ++k) increasing = table->x[k] > table->x[k - 1];
      if (!increasing) {
        return absl::InvalidArgumentError(absl::StrCat(
            "spring ", s.name, ": a force table needs 2 or more points, x strictly increasing, one force per x"));
      }
    }
  }
  for (const Driver& d : drivers) {
    if (d.profile.kind == Profile::Kind::kTabulated && d.profile.table.empty()) {
      return absl::InvalidArgumentError("a tabulated driver needs its table");
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
  for (const BeamElement& e : beams) {
    const int n = static_cast<int>(bodies.size());
    if (e.a < 0 || e.b < 0 || e.a >= n || e.b >= n || e.a == e.b) {
      return absl::InvalidArgumentError(absl::StrCat(e.name, ": its nodes must be two different bodies"));
    }
    if (!(e.length_m > 0.0) || !(e.axial_stiffness_n > 0.0) || !(e.bending_stiffness_n_m2 > 0.0) ||
        !std::isfinite(e.length_m + e.axial_stiffness_n + e.bending_stiffness_n_m2 + e.angle_a_rad + e.angle_b_rad)) {
      return absl::InvalidArgumentError(absl::StrCat(e.name, ": length, EA and EI must be finite and > 0, got ",
                                                     e.length_m, " m, ", e.axial_stiffness_n, " N, ",
                                                     e.bending_stiffness_n_m2, " N m^2"));
    }
  }
  return absl::OkStatus();
}

}  // namespace mbopt::multibody
