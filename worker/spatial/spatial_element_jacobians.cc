#include "worker/spatial/spatial_element_jacobians.h"

#include <cmath>
#include <optional>

#include "worker/spatial/euler_parameters.h"
#include "worker/spatial/pair_vectors.h"
#include "worker/spatial/spatial_force_elements.h"

namespace mbopt::spatial {
namespace {

using Eigen::Matrix3d;
using Eigen::Matrix4d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::Vector4d;
using Eigen::VectorXd;
using pair::kBlock;
using pair::PairHessian;
using pair::PairJacobian3;
using pair::PairRow;
using pair::PairScalar;

double FactorAt(const std::optional<multibody::Profile>& factor, double t) {
  return factor ? factor->At(t).q : 1.0;
}

// dT/dL and dT/dL' of SpringTension: the coefficients, or the slopes of
// the curves' segments that hold the deflection and the rate.
void TensionSlopes(const SpringDamper& s, double length, double rate, double* per_length, double* per_rate) {
  *per_length = s.deflection_curve.empty() ? s.stiffness_n_per_m : s.deflection_curve.Slope(length - s.free_length_m);
  *per_rate = s.velocity_curve.empty() ? s.damping_n_s_per_m : s.velocity_curve.Slope(rate);
}

// The spring's generalized force is Q = -T D^T u, with d = x_b - x_a (D its
// Jacobian over the pair), L = |d|, u = d / L, L' = u . d' and d' = D v.
// With P = (I - u u^T) / L (du/dq = P D) and the Euler parameters' terms
// sign A(p) s of d:
//   dL/dq = u^T D,  dL'/dq = d'^T P D + u^T d(D v)/dq,  dL'/dv = u^T D,
//   d(D v)/dq: sign d(A(p) s)/dp at p' (A is quadratic in p),
//   d(D^T u)/dq = D^T P D + sum of sign d2(u^T A(p) s)/dp2 (u held).
int AddSpringJacobians(const SpringDamper& s, const VectorXd& q, const VectorXd& v, bool continued, MatrixXd* q_q,
                       MatrixXd* q_v) {
  const pair::BodyCoordinates a = pair::CoordinatesOf(s.a.body, q, &v), b = pair::CoordinatesOf(s.b.body, q, &v);
  const pair::PairVector d =
      pair::Minus(pair::FixedIn(b, 1, s.b.position_m, true), pair::FixedIn(a, 0, s.a.position_m, true));
  const double length = d.x.norm();
  if (!(length > 0.0)) return 1;
  const Vector3d u = d.x / length;
  const double rate = u.dot(d.x_dot);
  const double tension = SpringTension(s, length, rate, continued);
  double per_length = 0.0, per_rate = 0.0;
  TensionSlopes(s, length, rate, &per_length, &per_rate);
  const Matrix3d across = (Matrix3d::Identity() - u * u.transpose()) / length;
  PairJacobian3 rate_of_jacobian = PairJacobian3::Zero();
  PairHessian curvature = PairHessian::Zero();
  for (int k = 0; k < d.num_terms; ++k) {
    const pair::QuadraticTerm& term = d.terms[static_cast<size_t>(k)];
    const int at = kBlock * term.slot + 3;
    const Vector4d& p_dot = term.slot == 0 ? a.p_dot : b.p_dot;
    rate_of_jacobian.block<3, 4>(0, at) += term.sign * RotatedVectorJacobian(p_dot, term.s);
    curvature.block<4, 4>(at, at) += term.sign * pair::QuadraticFormHessian(u, term.s);
  }
  const PairRow length_q = u.transpose() * d.jacobian;
  const PairRow rate_q = d.x_dot.transpose() * across * d.jacobian + u.transpose() * rate_of_jacobian;
  const PairRow tension_q = per_length * length_q + per_rate * rate_q;
  const Eigen::Matrix<double, pair::kPairColumns, 1> along = d.jacobian.transpose() * u;  // D^T u
  const PairHessian force_q =
      -along * tension_q - tension * (d.jacobian.transpose() * across * d.jacobian + curvature);
  const PairHessian force_v = -per_rate * along * length_q;
  if (!force_q.allFinite() || !force_v.allFinite()) return 1;
  pair::ScatterHessian(force_q, 1.0, s.a.body, s.b.body, q_q);
  pair::ScatterHessian(force_v, 1.0, s.a.body, s.b.body, q_v);
  return 0;
}

// Q_r = F, Q_p = (d(A(p) s)/dp)^T F: for F fixed in world axes
// dQ_p/dp = d2(F^T A(p) s)/dp2; for F = A(p) F0 (body axes) also
// dQ_r/dp = d(A(p) F0)/dp and (d(A s)/dp)^T d(A F0)/dp in dQ_p/dp.
void AddPointForceJacobian(const PointForce& f, double t, const VectorXd& q, MatrixXd* q_q) {
  if (f.at.body == kGround) return;
  const int at = kBlock * f.at.body;
  const Vector4d p = q.segment<4>(at + 3);
  const double factor = FactorAt(f.factor, t);
  const Vector3d force = factor * (f.body_axes ? Vector3d(RotationOf(p) * f.force_n) : f.force_n);
  Matrix4d p_p = pair::QuadraticFormHessian(force, f.at.position_m);
  if (f.body_axes) {
    const Matrix34d force_p = factor * RotatedVectorJacobian(p, f.force_n);
    q_q->block<3, 4>(at, at + 3) += force_p;
    p_p += RotatedVectorJacobian(p, f.at.position_m).transpose() * force_p;
  }
  q_q->block<4, 4>(at + 3, at + 3) += p_p;
}

// Q_p = 2 X(p)^T n with X = G (world axes) or L (body axes), linear in p:
// column k of dQ_p/dp is 2 X(e_k)^T n.
void AddTorqueJacobian(const BodyTorque& torque, double t, MatrixXd* q_q) {
  const int at = kBlock * torque.body + 3;
  const Vector3d n = FactorAt(torque.factor, t) * torque.torque_n_m;
  for (int k = 0; k < 4; ++k) {
    const Vector4d unit = Vector4d::Unit(k);
    q_q->block<4, 1>(at, at + k) +=
        2.0 * (torque.body_axes ? BodyRateMatrix(unit) : WorldRateMatrix(unit)).transpose() * n;
  }
}

// -x, with its derivatives.
PairScalar Negated(PairScalar x) {
  x.f = -x.f;
  x.jacobian = -x.jacobian;
  x.hessian = -x.hessian;
  return x;
}

// atan2(s, c) with its Jacobian J = (c J_s - s J_c) / rho, rho = c^2 + s^2,
// and its Hessian (c H_s - s H_c + J_s^T J_c - J_c^T J_s
// - 2 J^T (c J_c + s J_s)) / rho, symmetric up to round-off (made exact).
PairScalar Atan2(const PairScalar& s, const PairScalar& c) {
  const double rho = c.f * c.f + s.f * s.f;
  PairScalar out;
  out.f = std::atan2(s.f, c.f);
  out.jacobian = (c.f * s.jacobian - s.f * c.jacobian) / rho;
  const PairHessian h = (c.f * s.hessian - s.f * c.hessian + s.jacobian.transpose() * c.jacobian -
                         c.jacobian.transpose() * s.jacobian -
                         2.0 * out.jacobian.transpose() * (c.f * c.jacobian + s.f * s.jacobian)) /
                        rho;
  out.hessian = 0.5 * (h + h.transpose());
  return out;
}

// sqrt(x^2 + y^2): J = (x J_x + y J_y) / h,
// H = (J_x^T J_x + x H_x + J_y^T J_y + y H_y - J^T J) / h.
PairScalar Hypot(const PairScalar& x, const PairScalar& y) {
  PairScalar out;
  out.f = std::hypot(x.f, y.f);
  out.jacobian = (x.f * x.jacobian + y.f * y.jacobian) / out.f;
  out.hessian = (x.jacobian.transpose() * x.jacobian + x.f * x.hessian + y.jacobian.transpose() * y.jacobian +
                 y.f * y.hessian - out.jacobian.transpose() * out.jacobian) /
                out.f;
  return out;
}

// A measure m(q) of an element whose generalized force is
//   Q = g J^T,  g = -k m_elastic - c m',  m' = J v,
// with J and H m's Jacobian and Hessian over the pair and m_elastic m or,
// for a rotational spring, its turns-continued deflection (the same
// derivatives: the turn count is locally constant). Then
//   dQ/dq = J^T (-k J - c (H v)^T) + g H,  dQ/dv = -c J^T J.
void AddMeasureJacobians(const PairScalar& m, double elastic, double stiffness, double damping,
                         const Eigen::Matrix<double, pair::kPairColumns, 1>& rates, PairHessian* force_q,
                         PairHessian* force_v) {
  const double rate = m.jacobian.dot(rates);
  const double g = -stiffness * elastic - damping * rate;
  const PairRow rate_q = (m.hessian * rates).transpose();
  *force_q += m.jacobian.transpose() * (-stiffness * m.jacobian - damping * rate_q) + g * m.hessian;
  *force_v -= damping * m.jacobian.transpose() * m.jacobian;
}

// A rotational spring's angle atan2(x_b . y_a, x_b . x_a) over the joint's
// frames (spatial_force_elements.cc), k (theta - theta0) with theta
// following the turns as the force does.
int AddRotationalSpringJacobians(const Model& model, int index, const VectorXd& q, const VectorXd& v,
                                 SpringAngles* angles, MatrixXd* q_q, MatrixXd* q_v) {
  const RotationalSpringDamper& r = model.rotational_springs[static_cast<size_t>(index)];
  const Joint& joint = model.joints[static_cast<size_t>(r.joint)];
  const pair::FrameVectors a = pair::FrameOf(joint.a, 0, q, &v, true), b = pair::FrameOf(joint.b, 1, q, &v, true);
  const PairScalar angle = Atan2(pair::Dot(b.x, a.y), pair::Dot(b.x, a.x));
  const double deflection = angles->Follow(index, angle.f) - r.free_angle_rad;
  PairHessian force_q = PairHessian::Zero(), force_v = PairHessian::Zero();
  AddMeasureJacobians(angle, deflection, r.stiffness_n_m_per_rad, r.damping_n_m_s_per_rad,
                      pair::PairRates(joint.a.body, joint.b.body, v), &force_q, &force_v);
  if (!force_q.allFinite() || !force_v.allFinite()) return 1;
  pair::ScatterHessian(force_q, 1.0, joint.a.body, joint.b.body, q_q);
  pair::ScatterHessian(force_v, 1.0, joint.a.body, joint.b.body, q_v);
  return 0;
}

// A bushing's six measures: u_k = a_k . (o_b - o_a) and the x-y-z angles
// from R_ij = a_i . b_j (spatial_force_elements.cc):
//   theta_x = atan2(-R_12, R_22), theta_y = atan2(R_02, hypot(R_00, R_01)),
//   theta_z = atan2(-R_01, R_00),
// each a composition of dot products, whose Hessians are exact
// (pair_vectors.h), so the angles' second derivatives are too. Past the
// middle-angle limit, outside a continued scope, 1, as the force.
int AddBushingJacobians(const Bushing& bushing, const VectorXd& q, const VectorXd& v, bool continued, MatrixXd* q_q,
                        MatrixXd* q_v) {
  const pair::FrameVectors a = pair::FrameOf(bushing.a, 0, q, &v, true), b = pair::FrameOf(bushing.b, 1, q, &v, true);
  const pair::PairVector d = pair::Minus(b.origin, a.origin);
  const pair::PairVector* a_axes[3] = {&a.x, &a.y, &a.z};
  const Eigen::Matrix<double, pair::kPairColumns, 1> rates = pair::PairRates(bushing.a.body, bushing.b.body, v);
  PairHessian force_q = PairHessian::Zero(), force_v = PairHessian::Zero();
  for (int k = 0; k < 3; ++k) {
    const PairScalar u = pair::Dot(*a_axes[k], d);
    AddMeasureJacobians(u, u.f, bushing.stiffness_n_per_m[k], bushing.damping_n_s_per_m[k], rates, &force_q,
                        &force_v);
  }
  if (bushing.rotational_stiffness_n_m_per_rad.any() || bushing.rotational_damping_n_m_s_per_rad.any()) {
    const PairScalar r00 = pair::Dot(a.x, b.x), r01 = pair::Dot(a.x, b.y), r02 = pair::Dot(a.x, b.z);
    const PairScalar r12 = pair::Dot(a.y, b.z), r22 = pair::Dot(a.z, b.z);
    const PairScalar middle_cosine = Hypot(r00, r01);
    if (!continued && !(middle_cosine.f >= std::cos(kBushingMiddleAngleLimit_rad))) return 1;
    const PairScalar theta[3] = {Atan2(Negated(r12), r22), Atan2(r02, middle_cosine), Atan2(Negated(r01), r00)};
    for (int k = 0; k < 3; ++k) {
      AddMeasureJacobians(theta[k], theta[k].f, bushing.rotational_stiffness_n_m_per_rad[k],
                          bushing.rotational_damping_n_m_s_per_rad[k], rates, &force_q, &force_v);
    }
  }
  if (!force_q.allFinite() || !force_v.allFinite()) return 1;
  pair::ScatterHessian(force_q, 1.0, bushing.a.body, bushing.b.body, q_q);
  pair::ScatterHessian(force_v, 1.0, bushing.a.body, bushing.b.body, q_v);
  return 0;
}

}  // namespace

int AddElementJacobians(const Model& model, double t, const VectorXd& q, const VectorXd& v, bool continued,
                        SpringAngles* angles, MatrixXd* q_q, MatrixXd* q_v) {
  for (const SpringDamper& s : model.springs) {
    if (AddSpringJacobians(s, q, v, continued, q_q, q_v) != 0) return 1;
  }
  for (const PointForce& f : model.point_forces) AddPointForceJacobian(f, t, q, q_q);
  for (const BodyTorque& torque : model.torques) AddTorqueJacobian(torque, t, q_q);
  for (int k = 0; k < static_cast<int>(model.rotational_springs.size()); ++k) {
    if (AddRotationalSpringJacobians(model, k, q, v, angles, q_q, q_v) != 0) return 1;
  }
  for (const Bushing& b : model.bushings) {
    if (AddBushingJacobians(b, q, v, continued, q_q, q_v) != 0) return 1;
  }
  return q_q->allFinite() && q_v->allFinite() ? 0 : 1;
}

}  // namespace mbopt::spatial
