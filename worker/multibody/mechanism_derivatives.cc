// The derivatives of a Mechanism's equations that the integrator's Newton
// matrix needs (docs/physics.md, "The Newton matrix"): the second
// derivatives of the constraint rows, the force elements' stiffness and
// damping, and the co-rotational beams' tangent stiffness. Each is the
// exact derivative of what mechanism.cc evaluates; the tests compare them
// with difference quotients of it (tests/multibody/derivatives_test.cc).
#include <cmath>
#include <vector>

#include "worker/multibody/body_frame.h"
#include "worker/multibody/mechanism.h"

namespace mbopt::multibody {
namespace {

using Eigen::Matrix2d;
using Eigen::MatrixXd;
using Eigen::Vector2d;
using Eigen::VectorXd;
using frame::Frame;
using frame::FrameOf;

// d(point)/dq of point s on frame f: the 2 x 3 block at the body's columns,
// [I, B s].
Eigen::Matrix<double, 2, 3> PointGradient(const Frame& f, const Vector2d& s) {
  Eigen::Matrix<double, 2, 3> g;
  g << Matrix2d::Identity(), f.b * s;
  return g;
}

}  // namespace

void Mechanism::ConstraintSecondDerivatives(const VectorXd& q, std::vector<SecondDerivative>* out) const {
  out->clear();
  auto add = [&](int row, int j, int k, double value) {
    if (j < 0 || k < 0 || value == 0.0) return;
    out->push_back({row, j, k, value});
    if (j != k) out->push_back({row, k, j, value});
  };
  // f = (A_a u) . d, d = P_b - P_a: its only second derivatives are through
  // the rotation of body a (the axis and the marker on a) and of body b
  // (its marker). The angle rows (phi_b - phi_a) are linear.
  auto axis_row = [&](const Joint& joint, const Vector2d& local_axis, int row) {
    const Frame fa = FrameOf(joint.a.body, q, nullptr), fb = FrameOf(joint.b.body, q, nullptr);
    const Vector2d& sa = joint.a.local_m;
    const Vector2d& sb = joint.b.local_m;
    const Vector2d d = fb.Position(sb) - fa.Position(sa);
    const Vector2d axis = fa.a * local_axis, axis_rate = fa.b * local_axis;
    const int pa = fa.column < 0 ? -1 : fa.column + 2, pb = fb.column < 0 ? -1 : fb.column + 2;
    if (pa >= 0) {
      // B_a B_a = -I and B^T B = I make (B_a u).(B_a s_a) = u . s_a.
      add(row, pa, pa, -axis.dot(d) - local_axis.dot(sa));
      for (int i = 0; i < 2; ++i) {
        add(row, fa.column + i, pa, -axis_rate[i]);
        if (fb.column >= 0) add(row, fb.column + i, pa, axis_rate[i]);
      }
    }
    if (pb >= 0) {
      add(row, pb, pb, -axis.dot(fb.a * sb));
      if (pa >= 0) add(row, pa, pb, axis_rate.dot(fb.b * sb));
    }
  };
  for (size_t j = 0; j < model_.joints.size(); ++j) {
    const Joint& joint = model_.joints[j];
    const int row = joint_row_[j];
    if (joint.kind == JointKind::kPointOnLine || joint.kind == JointKind::kPrismatic) {
      axis_row(joint, Vector2d(-std::sin(joint.axis_angle_rad), std::cos(joint.axis_angle_rad)), row);
      continue;
    }
    // Revolute and fixed: P_a - P_b, curved only in each body's own angle.
    const Frame fa = FrameOf(joint.a.body, q, nullptr), fb = FrameOf(joint.b.body, q, nullptr);
    const Vector2d ca = -fa.a * joint.a.local_m, cb = fb.a * joint.b.local_m;
    for (int i = 0; i < 2; ++i) {
      if (fa.column >= 0) add(row + i, fa.column + 2, fa.column + 2, ca[i]);
      if (fb.column >= 0) add(row + i, fb.column + 2, fb.column + 2, cb[i]);
    }
  }
  for (size_t k = 0; k < model_.drivers.size(); ++k) {
    const Joint& joint = model_.joints[static_cast<size_t>(model_.drivers[k].joint)];
    if (joint.kind == JointKind::kPrismatic || joint.kind == JointKind::kPointOnLine) {
      axis_row(joint, Vector2d(std::cos(joint.axis_angle_rad), std::sin(joint.axis_angle_rad)), driver_row_[k]);
    }
  }
}

int Mechanism::ConstraintCurvature(double, const VectorXd& q, const VectorXd& w, MatrixXd* curvature) const {
  const int n = num_coordinates();
  curvature->setZero(n, n);
  std::vector<SecondDerivative> second;
  ConstraintSecondDerivatives(q, &second);
  for (const SecondDerivative& e : second) (*curvature)(e.j, e.k) += w[e.row] * e.value;
  return curvature->allFinite() ? 0 : 1;
}

// Phi_t depends on t only (a driver's prescribed value), so Phi_qt = 0 and
// d(Phi_q v + Phi_t)/dq is the rows' second derivatives applied to v.
int Mechanism::VelocityConstraintJacobian(double, const VectorXd& q, const VectorXd& v, MatrixXd* jacobian) const {
  jacobian->setZero(num_rows_, num_coordinates());
  std::vector<SecondDerivative> second;
  ConstraintSecondDerivatives(q, &second);
  for (const SecondDerivative& e : second) (*jacobian)(e.row, e.j) += e.value * v[e.k];
  return jacobian->allFinite() ? 0 : 1;
}

int Mechanism::ForceJacobians(double t, const VectorXd& q, const VectorXd& v, MatrixXd* q_q, MatrixXd* q_v) const {
  const int n = num_coordinates();
  q_q->setZero(n, n);
  q_v->setZero(n, n);
  // Gravity and body torques are constant. A constant world force f at
  // point s of a body gives (B s) . f on phi, whose derivative is -(A s) . f.
  for (const PointForce& f : model_.point_forces) {
    if (f.at.body == kGround || f.at.input >= 0) continue;
    const Frame frame = FrameOf(f.at.body, q, nullptr);
    const Vector2d force = f.factor ? Vector2d(f.force_n * f.factor->At(t).q) : f.force_n;
    (*q_q)(frame.column + 2, frame.column + 2) -= (frame.a * f.at.local_m).dot(force);
  }

  // Springs and dampers: Q = -G^T (T u), G = d(P_b - P_a)/dq, u the unit
  // vector from a to b, T the tension (of the length L and its rate L').
  for (size_t k = 0; k < model_.springs.size(); ++k) {
    const SpringDamper& s = model_.springs[k];
    struct End {
      Frame f;
      Vector2d local = Vector2d::Zero();
      double sign = 0.0;  // +1 for b, -1 for a, 0 for ground or an input point
    };
    const auto end_of = [&](const Point& p, double sign) {
      End e;
      if (p.input >= 0 || p.body == kGround) return e;
      e.f = FrameOf(p.body, q, &v);
      e.local = p.local_m;
      e.sign = sign;
      return e;
    };
    const End ends[2] = {end_of(s.a, -1.0), end_of(s.b, 1.0)};
    const Vector2d d = PointPosition(s.b, q, t) - PointPosition(s.a, q, t);
    const Vector2d d_dot = PointVelocity(s.b, q, v, t) - PointVelocity(s.a, q, v, t);
    const double length = d.norm();
    if (!(length > 0.0)) return 1;
    const Vector2d u = d / length;
    const double length_rate = u.dot(d_dot);
    const double tension = SpringTension(static_cast<int>(k), q, v, t);
    if (!std::isfinite(tension)) return 1;
    // dT/dL and dT/dL', the tables' segment slopes where they replace the
    // linear law (as SpringTension picks).
    const double k_length = s.deflection_curve.empty() ? s.stiffness_n_per_m
                                                       : s.deflection_curve.Slope(length - s.free_length_m);
    const double k_rate = s.velocity_curve.empty() ? s.damping_n_s_per_m : s.velocity_curve.Slope(length_rate);
    // G (2 x n) and dG/dq applied to the force and to v, over both ends.
    MatrixXd g = MatrixXd::Zero(2, n), g_v_q = MatrixXd::Zero(2, n);  // g_v_q = d(G v)/dq
    for (const End& e : ends) {
      if (e.sign == 0.0) continue;
      g.block<2, 3>(0, e.f.column) += e.sign * PointGradient(e.f, e.local);
      g_v_q.col(e.f.column + 2) -= e.sign * e.f.a * e.local * e.f.phi_dot;
    }
    const Matrix2d transverse = (Matrix2d::Identity() - u * u.transpose()) / length;  // du/dd
    const MatrixXd u_q = transverse * g;                                                  // du/dq
    const Eigen::RowVectorXd length_q = u.transpose() * g;
    const Eigen::RowVectorXd rate_q = d_dot.transpose() * u_q + u.transpose() * g_v_q;
    const Eigen::RowVectorXd tension_q = k_length * length_q + k_rate * rate_q;
    const Vector2d force = tension * u;
    *q_q -= g.transpose() * (u * tension_q + tension * u_q);
    for (const End& e : ends) {
      if (e.sign == 0.0) continue;
      (*q_q)(e.f.column + 2, e.f.column + 2) += e.sign * (e.f.a * e.local).dot(force);
    }
    *q_v -= k_rate * g.transpose() * u * length_q;
  }

  // Rotational springs (revolute joints): torque -k (phi_b - phi_a - theta0)
  // - c (phi_b' - phi_a') on b, the opposite on a.
  for (const RotationalSpringDamper& r : model_.rotational_springs) {
    const Joint& joint = model_.joints[static_cast<size_t>(r.joint)];
    const int columns[2] = {joint.a.body == kGround ? -1 : 3 * joint.a.body + 2,
                            joint.b.body == kGround ? -1 : 3 * joint.b.body + 2};
    const double signs[2] = {-1.0, 1.0};
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) {
        if (columns[i] < 0 || columns[j] < 0) continue;
        (*q_q)(columns[i], columns[j]) -= signs[i] * signs[j] * r.stiffness_n_m_per_rad;
        (*q_v)(columns[i], columns[j]) -= signs[i] * signs[j] * r.damping_n_m_s_per_rad;
      }
    }
  }

  // Co-rotational beams: f = B^T L with B = d(u, theta_a, theta_b)/dx (rows
  // r, e3 - z/l, e6 - z/l) and the loads L = D (B x-deformation) + beta D
  // (B x'). df/dx = B^T D B + beta B^T D (d(B x')/dx) + the geometric
  // stiffness N z z^T / l + (Ma + Mb)(r z^T + z r^T) / l^2 (Crisfield,
  // section 7.2); df/dx' = beta B^T D B. The element applies -f.
  for (const BeamElement& e : model_.beams) {
    const BeamNodes x = BeamCoordinates(e, q), x_dot = BeamCoordinates(e, v);
    BeamLoads loads;
    if (!EvaluateBeam(e, x, &x_dot, &loads)) return 1;
    const double l = loads.chord_length_m, c = loads.chord_cos, s = loads.chord_sin;
    BeamNodes r, z;
    r << -c, -s, 0.0, c, s, 0.0;
    z << s, -c, 0.0, -s, c, 0.0;
    Eigen::Matrix<double, 3, 6> b;
    b.row(0) = r.transpose();
    b.row(1) = -z.transpose() / l;
    b.row(2) = -z.transpose() / l;
    b(1, 2) += 1.0;
    b(2, 5) += 1.0;
    const double k_bend = 2.0 * e.bending_stiffness_n_m2 / e.length_m;
    Eigen::Matrix3d dmat;
    dmat << e.axial_stiffness_n / e.length_m, 0.0, 0.0, 0.0, 2.0 * k_bend, k_bend, 0.0, k_bend, 2.0 * k_bend;
    Eigen::Matrix<double, 6, 6> stiffness = b.transpose() * dmat * b;
    stiffness += loads.axial_n * z * z.transpose() / l +
                 (loads.moment_a_n_m + loads.moment_b_n_m) * (r * z.transpose() + z * r.transpose()) / (l * l);
    Eigen::Matrix<double, 6, 6> damping = Eigen::Matrix<double, 6, 6>::Zero();
    if (e.damping_s > 0.0) {
      const double r_rate = r.dot(x_dot), z_rate = z.dot(x_dot);
      Eigen::Matrix<double, 3, 6> rate_x;  // d(B x')/dx
      rate_x.row(0) = z_rate * z.transpose() / l;
      rate_x.row(1) = (r_rate * z.transpose() + z_rate * r.transpose()) / (l * l);
      rate_x.row(2) = rate_x.row(1);
      stiffness += e.damping_s * b.transpose() * dmat * rate_x;
      damping = e.damping_s * b.transpose() * dmat * b;
    }
    const int columns[2] = {3 * e.a, 3 * e.b};
    for (int i = 0; i < 2; ++i) {
      for (int j = 0; j < 2; ++j) {
        q_q->block<3, 3>(columns[i], columns[j]) -= stiffness.block<3, 3>(3 * i, 3 * j);
        q_v->block<3, 3>(columns[i], columns[j]) -= damping.block<3, 3>(3 * i, 3 * j);
      }
    }
  }
  return q_q->allFinite() && q_v->allFinite() ? 0 : 1;
}

void Mechanism::DerivativePattern(Pattern* coupling, Pattern* rows) const {
  const int n = num_coordinates();
  coupling->setConstant(n, n, false);
  rows->setConstant(num_rows_, n, false);
  auto couple = [&](int body_a, int body_b) {
    for (int i : {body_a, body_b}) {
      for (int j : {body_a, body_b}) {
        if (i != kGround && j != kGround) coupling->block(3 * i, 3 * j, 3, 3) = true;
      }
    }
  };
  auto body_of = [](const Point& p) { return p.input >= 0 ? kGround : p.body; };
  for (size_t i = 0; i < model_.bodies.size(); ++i) couple(static_cast<int>(i), static_cast<int>(i));
  for (const Joint& joint : model_.joints) couple(joint.a.body, joint.b.body);
  for (const SpringDamper& s : model_.springs) couple(body_of(s.a), body_of(s.b));
  for (const BeamElement& e : model_.beams) couple(e.a, e.b);
  for (int row = 0; row < num_rows_; ++row) {
    const Joint& joint = model_.joints[static_cast<size_t>(row_joint_[static_cast<size_t>(row)])];
    for (int body : {joint.a.body, joint.b.body}) {
      if (body != kGround) rows->block(row, 3 * body, 1, 3) = true;
    }
  }
}

}  // namespace mbopt::multibody
