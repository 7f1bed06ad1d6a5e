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

}  // namespace

bool HasAnalyticElementJacobians(const Model& model) {
  return model.rotational_springs.empty() && model.bushings.empty();
}

int AddElementJacobians(const Model& model, double t, const VectorXd& q, const VectorXd& v, bool continued,
                        MatrixXd* q_q, MatrixXd* q_v) {
  for (const SpringDamper& s : model.springs) {
    if (AddSpringJacobians(s, q, v, continued, q_q, q_v) != 0) return 1;
  }
  for (const PointForce& f : model.point_forces) AddPointForceJacobian(f, t, q, q_q);
  for (const BodyTorque& torque : model.torques) AddTorqueJacobian(torque, t, q_q);
  return q_q->allFinite() && q_v->allFinite() ? 0 : 1;
}

}  // namespace mbopt::spatial
