#include "worker/spatial/spatial_force_elements.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "worker/spatial/euler_parameters.h"
#include "worker/spatial/spatial_system.h"

namespace mbopt::spatial {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::Vector4d;
using Eigen::VectorXd;

constexpr int kBlock = SpatialSystem::kCoordinatesPerBody;
// An element joins two bodies: columns 0-6 are body a's coordinates, 7-13
// body b's (zero for ground).
constexpr int kPair = 2 * kBlock;
using PairRow = Eigen::Matrix<double, 1, kPair>;
using PairRows = Eigen::Matrix<double, 3, kPair>;

// A vector fixed in a body (or a point, with its origin) in world axes and
// its derivative over the pair's coordinates.
struct Tracked {
  Vector3d x = Vector3d::Zero();
  PairRows jacobian = PairRows::Zero();
};

struct Tracked1 {
  double f = 0.0;
  PairRow jacobian = PairRow::Zero();
};

Vector4d ParametersOf(int body, const VectorXd& q) {
  return body == kGround ? Vector4d(1.0, 0.0, 0.0, 0.0) : Vector4d(q.segment<4>(kBlock * body + 3));
}

Tracked FixedIn(int body, int slot, const Vector3d& s, bool point, const VectorXd& q) {
  Tracked out;
  const Vector4d p = ParametersOf(body, q);
  out.x = RotationOf(p) * s;
  if (body == kGround) return out;
  if (point) {
    out.x += q.segment<3>(kBlock * body);
    out.jacobian.block<3, 3>(0, kBlock * slot).setIdentity();
  }
  out.jacobian.block<3, 4>(0, kBlock * slot + 3) = RotatedVectorJacobian(p, s);
  return out;
}

Tracked1 Dot(const Tracked& a, const Tracked& b) {
  return {a.x.dot(b.x), b.x.transpose() * a.jacobian + a.x.transpose() * b.jacobian};
}

// The pair's velocities (ground: zero).
Eigen::Matrix<double, kPair, 1> PairVelocity(int body_a, int body_b, const VectorXd& v) {
  Eigen::Matrix<double, kPair, 1> out = Eigen::Matrix<double, kPair, 1>::Zero();
  if (body_a != kGround) out.head<kBlock>() = v.segment<kBlock>(kBlock * body_a);
  if (body_b != kGround) out.tail<kBlock>() = v.segment<kBlock>(kBlock * body_b);
  return out;
}

void Scatter(const PairRow& generalized, int body_a, int body_b, VectorXd* forces) {
  if (body_a != kGround) forces->segment<kBlock>(kBlock * body_a) += generalized.head<kBlock>().transpose();
  if (body_b != kGround) forces->segment<kBlock>(kBlock * body_b) += generalized.tail<kBlock>().transpose();
}

// A rotational spring's joint angle theta (in (-pi, pi]) and dtheta/dq, as
// SpatialSystem::JointAngle: atan2(x_b . y_a, x_b . x_a).
struct JointAngleOf {
  Tracked1 angle;
  int body_a = kGround, body_b = kGround;
};

// atan2(s, c) and its derivative (c ds - s dc) / (c^2 + s^2).
Tracked1 Atan2(const Tracked1& s, const Tracked1& c) {
  return {std::atan2(s.f, c.f), (c.f * s.jacobian - s.f * c.jacobian) / (c.f * c.f + s.f * s.f)};
}

JointAngleOf AngleOf(const Model& model, int joint, const VectorXd& q) {
  const Joint& j = model.joints[static_cast<size_t>(joint)];
  const Tracked xa = FixedIn(j.a.body, 0, j.a.axes.col(0), false, q);
  const Tracked ya = FixedIn(j.a.body, 0, j.a.axes.col(1), false, q);
  const Tracked xb = FixedIn(j.b.body, 1, j.b.axes.col(0), false, q);
  JointAngleOf out;
  out.body_a = j.a.body;
  out.body_b = j.b.body;
  out.angle = Atan2(Dot(xb, ya), Dot(xb, xa));
  return out;
}

// theta - theta0 with theta continuous along the motion (SpringAngles).
double Deflection(const RotationalSpringDamper& spring, int index, double principal, SpringAngles* angles) {
  return angles->Follow(index, principal) - spring.free_angle_rad;
}

bool HasRotation(const Bushing& b) {
  return b.rotational_stiffness_n_m_per_rad.any() || b.rotational_damping_n_m_s_per_rad.any();
}

// A bushing's u and theta (value and Jacobian per component), and cos of
// the middle angle (theta's Jacobians are not computed for a bushing
// without rotational terms).
struct BushingMeasures {
  Tracked1 u[3], theta[3];
  double middle_cosine = 1.0;
};

BushingMeasures MeasuresOf(const Bushing& b, const VectorXd& q) {
  const Tracked oa = FixedIn(b.a.body, 0, b.a.position_m, true, q);
  const Tracked ob = FixedIn(b.b.body, 1, b.b.position_m, true, q);
  Tracked d;
  d.x = ob.x - oa.x;
  d.jacobian = ob.jacobian - oa.jacobian;
  Tracked a[3], c[3];
  for (int k = 0; k < 3; ++k) {
    a[k] = FixedIn(b.a.body, 0, b.a.axes.col(k), false, q);
    c[k] = FixedIn(b.b.body, 1, b.b.axes.col(k), false, q);
  }
  BushingMeasures m;
  for (int k = 0; k < 3; ++k) m.u[k] = Dot(a[k], d);
  if (!HasRotation(b)) return m;
  // R_ij = a_i . b_j = (Rx(t0) Ry(t1) Rz(t2))_ij, whose first row is
  // (c1 c2, -c1 s2, s1) and last column (s1, -s0 c1, c0 c1).
  const Tracked1 r00 = Dot(a[0], c[0]), r01 = Dot(a[0], c[1]), r02 = Dot(a[0], c[2]);
  const Tracked1 r12 = Dot(a[1], c[2]), r22 = Dot(a[2], c[2]);
  const auto minus = [](const Tracked1& x) { return Tracked1{-x.f, -x.jacobian}; };
  Tracked1 cos1;
  cos1.f = std::hypot(r00.f, r01.f);
  cos1.jacobian = (r00.f * r00.jacobian + r01.f * r01.jacobian) / cos1.f;
  m.middle_cosine = cos1.f;
  m.theta[0] = Atan2(minus(r12), r22);
  m.theta[1] = Atan2(r02, cos1);
  m.theta[2] = Atan2(minus(r01), r00);
  return m;
}

// The couple on b (a's axes) whose power equals that of the angles'
// generalized forces f: with omega = W(theta) dtheta/dt the relative
// angular velocity in a's axes, W's columns x, Rx(t0) y and Rx(t0) Ry(t1) z,
// the couple solves W^T m = f.
Vector3d CoupleOf(const Vector3d& theta, const Vector3d& f) {
  const double c0 = std::cos(theta[0]), s0 = std::sin(theta[0]);
  const double c1 = std::cos(theta[1]), s1 = std::sin(theta[1]);
  const double g = (f[2] - s1 * f[0]) / c1;
  return Vector3d(f[0], c0 * f[1] - s0 * g, s0 * f[1] + c0 * g);
}

// The force, the couple and the angles' generalized forces f_theta.
struct BushingEffort {
  BushingLoad load;
  Vector3d angle_forces = Vector3d::Zero();
};

BushingEffort EffortOf(const Bushing& b, const BushingMeasures& m, const Eigen::Matrix<double, kPair, 1>& v) {
  BushingEffort e;
  for (int k = 0; k < 3; ++k) {
    e.load.force_n[k] = -b.stiffness_n_per_m[k] * m.u[k].f - b.damping_n_s_per_m[k] * m.u[k].jacobian.dot(v);
    e.load.angles_rad[k] = m.theta[k].f;
    e.angle_forces[k] = -b.rotational_stiffness_n_m_per_rad[k] * m.theta[k].f -
                        b.rotational_damping_n_m_s_per_rad[k] * m.theta[k].jacobian.dot(v);
  }
  if (HasRotation(b)) e.load.moment_n_m = CoupleOf(e.load.angles_rad, e.angle_forces);
  return e;
}

double FactorAt(const std::optional<multibody::Profile>& factor, double t) {
  return factor ? factor->At(t).q : 1.0;
}

absl::Status CheckBody(const Model& m, int body, const std::string& where, bool ground_allowed) {
  if (body < (ground_allowed ? kGround : 0) || body >= static_cast<int>(m.bodies.size())) {
    return absl::InvalidArgumentError(absl::StrFormat("%s: body index %d is not %sone of the %d bodies", where, body,
                                                      ground_allowed ? "ground (-1) or " : "", m.bodies.size()));
  }
  return absl::OkStatus();
}

absl::Status CheckFactor(const std::optional<multibody::Profile>& factor, const std::string& where) {
  if (factor && factor->kind == multibody::Profile::Kind::kTabulated && factor->table.empty()) {
    return absl::InvalidArgumentError(where + ": tabulated time factor without a table");
  }
  return absl::OkStatus();
}

bool NotNegative(const Vector3d& v) { return v.allFinite() && v.minCoeff() >= 0.0; }

// A spring's length and its rate.
void LengthAndRate(const SpringDamper& s, const VectorXd& q, const VectorXd& v, double* length, double* rate) {
  const Tracked a = FixedIn(s.a.body, 0, s.a.position_m, true, q), b = FixedIn(s.b.body, 1, s.b.position_m, true, q);
  const Vector3d d = b.x - a.x;
  *length = d.norm();
  const Vector3d d_dot = (b.jacobian - a.jacobian) * PairVelocity(s.a.body, s.b.body, v);
  *rate = *length > 0.0 ? d.dot(d_dot) / *length : 0.0;
}

// The integral of a piecewise-linear curve, continued past its ends, from
// 0 to x: exact by trapezoids between its breakpoints.
double IntegralFromZero(const multibody::LinearTable& curve, double x) {
  std::vector<double> at = {0.0, x};
  for (double k : curve.x) {
    if ((k > 0.0 && k < x) || (k < 0.0 && k > x)) at.push_back(k);
  }
  std::sort(at.begin(), at.end());
  double sum = 0.0;
  for (size_t k = 1; k < at.size(); ++k) {
    sum += 0.5 * (at[k] - at[k - 1]) * (curve.Continued(at[k]) + curve.Continued(at[k - 1]));
  }
  return x >= 0.0 ? sum : -sum;
}

struct CurveBound {
  int spring = 0;
  bool velocity = false, upper = false;
};

std::vector<CurveBound> CurveBoundsOf(const Model& model) {
  std::vector<CurveBound> bounds;
  for (size_t k = 0; k < model.springs.size(); ++k) {
    const SpringDamper& s = model.springs[k];
    for (const bool velocity : {false, true}) {
      if ((velocity ? s.velocity_curve : s.deflection_curve).empty()) continue;
      bounds.push_back(CurveBound{static_cast<int>(k), velocity, false});
      bounds.push_back(CurveBound{static_cast<int>(k), velocity, true});
    }
  }
  return bounds;
}

absl::Status CheckCurve(const multibody::LinearTable& curve, const std::string& where) {
  if (curve.empty()) return absl::OkStatus();
  bool ok = curve.x.size() >= 2 && curve.x.size() == curve.y.size();
  for (size_t k = 0; ok && k < curve.x.size(); ++k) {
    ok = std::isfinite(curve.x[k]) && std::isfinite(curve.y[k]) && (k == 0 || curve.x[k] > curve.x[k - 1]);
  }
  if (!ok) {
    return absl::InvalidArgumentError(where + ": expected at least 2 finite points, abscissae strictly increasing");
  }
  return absl::OkStatus();
}

}  // namespace

double SpringTension(const SpringDamper& s, double length_m, double rate_m_per_s, bool continued) {
  const double deflection = length_m - s.free_length_m;
  double elastic = s.stiffness_n_per_m * deflection, viscous = s.damping_n_s_per_m * rate_m_per_s;
  if (continued) {
    if (!s.deflection_curve.empty()) elastic = s.deflection_curve.Continued(deflection);
    if (!s.velocity_curve.empty()) viscous = s.velocity_curve.Continued(rate_m_per_s);
  } else {
    if (!s.deflection_curve.empty() && !s.deflection_curve.Evaluate(deflection, &elastic)) return NAN;
    if (!s.velocity_curve.empty() && !s.velocity_curve.Evaluate(rate_m_per_s, &viscous)) return NAN;
  }
  return elastic + viscous + s.actuator_force_n;
}

double SpringStrainEnergy(const SpringDamper& s, double length_m) {
  const double deflection = length_m - s.free_length_m;
  const double elastic = s.deflection_curve.empty() ? 0.5 * s.stiffness_n_per_m * deflection * deflection
                                                    : IntegralFromZero(s.deflection_curve, deflection);
  return elastic + s.actuator_force_n * length_m;
}

int SpringCurveBoundCount(const Model& model) { return static_cast<int>(CurveBoundsOf(model).size()); }

void SpringCurveBounds(const Model& model, const VectorXd& q, const VectorXd& v, double* g) {
  const std::vector<CurveBound> bounds = CurveBoundsOf(model);
  for (size_t k = 0; k < bounds.size(); ++k) {
    const CurveBound& b = bounds[k];
    const SpringDamper& s = model.springs[static_cast<size_t>(b.spring)];
    double length = 0.0, rate = 0.0;
    LengthAndRate(s, q, v, &length, &rate);
    const multibody::LinearTable& table = b.velocity ? s.velocity_curve : s.deflection_curve;
    const double at = b.velocity ? rate : length - s.free_length_m;
    g[k] = b.upper ? table.x.back() - at : at - table.x.front();
  }
}

std::string SpringCurveBoundReason(const Model& model, int bound, double t, const VectorXd& q, const VectorXd& v) {
  const std::vector<CurveBound> bounds = CurveBoundsOf(model);
  if (bound < 0 || bound >= static_cast<int>(bounds.size())) return "";
  const CurveBound& b = bounds[static_cast<size_t>(bound)];
  const SpringDamper& s = model.springs[static_cast<size_t>(b.spring)];
  double length = 0.0, rate = 0.0;
  LengthAndRate(s, q, v, &length, &rate);
  const multibody::LinearTable& table = b.velocity ? s.velocity_curve : s.deflection_curve;
  const char* unit = b.velocity ? "m/s" : "m";
  return absl::StrFormat(
      "spring '%s' left the range of its force table at t = %.6g s: its %s reached %.6g %s, the %s end of the "
      "table (%.6g..%.6g %s)",
      s.name, t, b.velocity ? "rate of length change" : "deflection", b.velocity ? rate : length - s.free_length_m,
      unit, b.upper ? "upper" : "lower", table.x.front(), table.x.back(), unit);
}

absl::Status ValidateForceElements(const Model& model) {
  for (const SpringDamper& s : model.springs) {
    const std::string where = "spring-damper '" + s.name + "'";
    if (absl::Status st = CheckCurve(s.deflection_curve, where + ", deflection curve"); !st.ok()) return st;
    if (absl::Status st = CheckCurve(s.velocity_curve, where + ", velocity curve"); !st.ok()) return st;
    if (!std::isfinite(s.actuator_force_n)) return absl::InvalidArgumentError(where + ": actuator force is not finite");
  }
  for (const PointForce& f : model.point_forces) {
    const std::string where = "point force '" + f.name + "'";
    if (absl::Status s = CheckBody(model, f.at.body, where, true); !s.ok()) return s;
    if (!f.force_n.allFinite() || !f.at.position_m.allFinite()) {
      return absl::InvalidArgumentError(where + ": force or point is not finite");
    }
    if (absl::Status s = CheckFactor(f.factor, where); !s.ok()) return s;
  }
  for (const BodyTorque& t : model.torques) {
    const std::string where = "torque '" + t.name + "'";
    if (absl::Status s = CheckBody(model, t.body, where, false); !s.ok()) return s;
    if (!t.torque_n_m.allFinite()) return absl::InvalidArgumentError(where + ": torque is not finite");
    if (absl::Status s = CheckFactor(t.factor, where); !s.ok()) return s;
  }
  for (const RotationalSpringDamper& r : model.rotational_springs) {
    const std::string where = "rotational spring '" + r.name + "'";
    if (r.joint < 0 || r.joint >= static_cast<int>(model.joints.size())) {
      return absl::InvalidArgumentError(absl::StrFormat("%s: joint index %d is not one of the %d joints", where,
                                                        r.joint, model.joints.size()));
    }
    const Joint& joint = model.joints[static_cast<size_t>(r.joint)];
    if (joint.kind != Joint::Kind::kRevolute && joint.kind != Joint::Kind::kCylindrical) {
      return absl::InvalidArgumentError(where + ": acts at " + JointKindName(joint.kind) + " joint '" + joint.name +
                                        "', expected a revolute or cylindrical joint (its angle)");
    }
    if (!(r.stiffness_n_m_per_rad >= 0.0) || !(r.damping_n_m_s_per_rad >= 0.0) ||
        !std::isfinite(r.stiffness_n_m_per_rad + r.damping_n_m_s_per_rad + r.free_angle_rad)) {
      return absl::InvalidArgumentError(
          absl::StrFormat("%s: stiffness %g N m/rad, damping %g N m s/rad, free angle %g rad: expected finite "
                          "values, the first two >= 0",
                          where, r.stiffness_n_m_per_rad, r.damping_n_m_s_per_rad, r.free_angle_rad));
    }
  }
  for (const Bushing& b : model.bushings) {
    const std::string where = "bushing '" + b.name + "'";
    if (absl::Status s = CheckBody(model, b.a.body, where + ", frame a", true); !s.ok()) return s;
    if (absl::Status s = CheckBody(model, b.b.body, where + ", frame b", true); !s.ok()) return s;
    if (b.a.body == b.b.body) {
      return absl::InvalidArgumentError(where + ": both frames are on " + model.BodyName(b.a.body) +
                                        ", expected two different bodies");
    }
    if (!b.a.position_m.allFinite() || !b.b.position_m.allFinite() || !b.a.axes.allFinite() ||
        !b.b.axes.allFinite()) {
      return absl::InvalidArgumentError(where + ": a frame is not finite");
    }
    if (!NotNegative(b.stiffness_n_per_m) || !NotNegative(b.damping_n_s_per_m) ||
        !NotNegative(b.rotational_stiffness_n_m_per_rad) || !NotNegative(b.rotational_damping_n_m_s_per_rad)) {
      return absl::InvalidArgumentError(where + ": stiffnesses and dampings must be finite and >= 0");
    }
  }
  return absl::OkStatus();
}

double SpringAngles::Follow(int spring, double principal_rad) {
  double& latest = latest_rad_[static_cast<size_t>(spring)];
  const double turns = std::round((latest - principal_rad) / (2.0 * std::numbers::pi));
  latest = principal_rad + 2.0 * std::numbers::pi * turns;
  return latest;
}

int AddForceElementForces(const Model& model, double t, const VectorXd& q, const VectorXd& v, bool continued,
                          SpringAngles* angles, VectorXd* forces, std::string* failure) {
  for (const PointForce& f : model.point_forces) {
    if (f.at.body == kGround) continue;  // ground takes it
    const int at = kBlock * f.at.body;
    const Vector4d p = q.segment<4>(at + 3);
    const Vector3d force = FactorAt(f.factor, t) * (f.body_axes ? Vector3d(RotationOf(p) * f.force_n) : f.force_n);
    forces->segment<3>(at) += force;
    // Its moment about the centre of mass, in Euler-parameter form.
    forces->segment<4>(at + 3) += RotatedVectorJacobian(p, f.at.position_m).transpose() * force;
  }
  for (const BodyTorque& torque : model.torques) {
    const int at = kBlock * torque.body;
    const Vector4d p = q.segment<4>(at + 3);
    const Vector3d n = FactorAt(torque.factor, t) * torque.torque_n_m;
    // omega = 2 G p' (world) = 2 L p' (body): the virtual work n . delta pi
    // is (2 G^T n) . delta p.
    forces->segment<4>(at + 3) +=
        2.0 * (torque.body_axes ? BodyRateMatrix(p) : WorldRateMatrix(p)).transpose() * n;
  }
  for (size_t k = 0; k < model.rotational_springs.size(); ++k) {
    const RotationalSpringDamper& r = model.rotational_springs[k];
    const JointAngleOf a = AngleOf(model, r.joint, q);
    const double rate = a.angle.jacobian.dot(PairVelocity(a.body_a, a.body_b, v));
    const double torque = -r.stiffness_n_m_per_rad * Deflection(r, static_cast<int>(k), a.angle.f, angles) -
                          r.damping_n_m_s_per_rad * rate;
    Scatter(torque * a.angle.jacobian, a.body_a, a.body_b, forces);
  }
  for (const Bushing& b : model.bushings) {
    const BushingMeasures m = MeasuresOf(b, q);
    if (!continued && !(m.middle_cosine >= std::cos(kBushingMiddleAngleLimit_rad))) {
      if (failure != nullptr) {
        *failure = absl::StrFormat(
            "bushing '%s': the middle of its x-y-z angles reached %.6g deg, past the %.6g deg the bushing is "
            "defined to (its angles are singular at 90 deg)",
            b.name, std::acos(std::min(1.0, m.middle_cosine)) * 180.0 / std::numbers::pi,
            kBushingMiddleAngleLimit_rad * 180.0 / std::numbers::pi);
      }
      return 1;
    }
    const BushingEffort e = EffortOf(b, m, PairVelocity(b.a.body, b.b.body, v));
    PairRow generalized = PairRow::Zero();
    for (int k = 0; k < 3; ++k) {
      generalized += e.load.force_n[k] * m.u[k].jacobian;
      if (HasRotation(b)) generalized += e.angle_forces[k] * m.theta[k].jacobian;
    }
    Scatter(generalized, b.a.body, b.b.body, forces);
  }
  return forces->allFinite() ? 0 : 1;
}

double ForceElementPotentialEnergy(const Model& model, const VectorXd& q, SpringAngles* angles) {
  double energy = 0.0;
  for (size_t k = 0; k < model.rotational_springs.size(); ++k) {
    const RotationalSpringDamper& r = model.rotational_springs[k];
    const double deflection = Deflection(r, static_cast<int>(k), AngleOf(model, r.joint, q).angle.f, angles);
    energy += 0.5 * r.stiffness_n_m_per_rad * deflection * deflection;
  }
  for (const Bushing& b : model.bushings) {
    const BushingMeasures m = MeasuresOf(b, q);
    for (int k = 0; k < 3; ++k) {
      energy += 0.5 * (b.stiffness_n_per_m[k] * m.u[k].f * m.u[k].f +
                       b.rotational_stiffness_n_m_per_rad[k] * m.theta[k].f * m.theta[k].f);
    }
  }
  return energy;
}

double RotationalSpringTorque(const Model& model, int spring, const VectorXd& q, const VectorXd& v,
                              SpringAngles* angles) {
  const RotationalSpringDamper& r = model.rotational_springs[static_cast<size_t>(spring)];
  const JointAngleOf a = AngleOf(model, r.joint, q);
  const double rate = a.angle.jacobian.dot(PairVelocity(a.body_a, a.body_b, v));
  return -r.stiffness_n_m_per_rad * Deflection(r, spring, a.angle.f, angles) - r.damping_n_m_s_per_rad * rate;
}

BushingLoad BushingLoadOf(const Model& model, int bushing, const VectorXd& q, const VectorXd& v) {
  const Bushing& b = model.bushings[static_cast<size_t>(bushing)];
  return EffortOf(b, MeasuresOf(b, q), PairVelocity(b.a.body, b.b.body, v)).load;
}

int BushingAngleBoundCount(const Model& model) {
  return static_cast<int>(std::count_if(model.bushings.begin(), model.bushings.end(), HasRotation));
}

void BushingAngleBounds(const Model& model, const VectorXd& q, double* g) {
  int k = 0;
  for (const Bushing& b : model.bushings) {
    if (HasRotation(b)) g[k++] = MeasuresOf(b, q).middle_cosine - std::cos(kBushingMiddleAngleLimit_rad);
  }
}

std::string BushingAngleBoundReason(const Model& model, int bound, double t, const VectorXd& q) {
  int k = 0;
  for (const Bushing& b : model.bushings) {
    if (!HasRotation(b) || k++ != bound) continue;
    return absl::StrFormat(
        "bushing '%s' reached the limit of its rotation measure at t = %.6g s: the middle of its x-y-z angles "
        "reached %.6g deg (limit %.6g deg; the angles are singular at 90 deg)",
        b.name, t, MeasuresOf(b, q).theta[1].f * 180.0 / std::numbers::pi,
        kBushingMiddleAngleLimit_rad * 180.0 / std::numbers::pi);
  }
  return "";
}

}  // namespace mbopt::spatial
