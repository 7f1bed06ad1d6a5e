// SpatialSystem's Newton-matrix derivatives (docs/physics.md section 8,
// "Newton matrix"): the constraints' curvature d(Phi_q^T w)/dq and the
// velocity constraints' Jacobian d(Phi_q v + Phi_t)/dq from the equations'
// exact Hessians (pair_vectors.h), the Euler parameters' mass matrix
// d(M(q) a)/dq and quadratic velocity terms analytically, and the force
// elements' Jacobians analytically (spatial_element_jacobians.h).
#include <cmath>

#include "worker/spatial/euler_parameters.h"
#include "worker/spatial/pair_vectors.h"
#include "worker/spatial/spatial_element_jacobians.h"
#include "worker/spatial/spatial_force_elements.h"
#include "worker/spatial/spatial_system.h"

namespace mbopt::spatial {
namespace {

using Eigen::Matrix3d;
using Eigen::Matrix4d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::Vector4d;
using Eigen::VectorXd;
using pair::kBlock;
using pair::PairRow;
using pair::PairScalar;

// A joint or driver row with its Hessian and the derivative of its Phi_t
// in q.
struct RowWithHessian {
  int row = 0;
  int body_a = kGround, body_b = kGround;
  PairScalar equation;
  PairRow phi_t_q = PairRow::Zero();
};

std::vector<RowWithHessian> RowsWithHessians(const SpatialSystem& system, double t, const VectorXd& q) {
  const Model& model = system.model();
  std::vector<RowWithHessian> out;
  for (size_t j = 0; j < model.joints.size(); ++j) {
    const Joint& joint = model.joints[j];
    const std::vector<PairScalar> rows = pair::JointEquations(joint, q, nullptr, true);
    for (size_t k = 0; k < rows.size(); ++k) {
      out.push_back({system.first_row_of_joint(static_cast<int>(j)) + static_cast<int>(k), joint.a.body,
                     joint.b.body, rows[k], PairRow::Zero()});
    }
  }
  for (size_t d = 0; d < model.drivers.size(); ++d) {
    const Joint& joint = model.joints[static_cast<size_t>(model.drivers[d].joint)];
    const pair::FrameVectors a = pair::FrameOf(joint.a, 0, q, nullptr, true);
    const pair::FrameVectors b = pair::FrameOf(joint.b, 1, q, nullptr, true);
    const multibody::Profile::Value value = model.drivers[d].profile.At(t);
    RowWithHessian r{system.row_of_driver(static_cast<int>(d)), joint.a.body, joint.b.body, {}, PairRow::Zero()};
    if (model.drivers[d].slide) {
      // z_a.d - s(t): Phi_t = -s' does not depend on q.
      r.equation = pair::Dot(a.z, pair::Minus(b.origin, a.origin));
    } else {
      // cos(theta) sine - sin(theta) cosine (spatial_system.cc), with
      // Phi_t = -theta' (sin(theta) sine + cos(theta) cosine).
      const PairScalar sine = pair::Dot(b.x, a.y), cosine = pair::Dot(b.x, a.x);
      const double c = std::cos(value.q), s = std::sin(value.q);
      r.equation.jacobian = c * sine.jacobian - s * cosine.jacobian;
      r.equation.hessian = c * sine.hessian - s * cosine.hessian;
      r.phi_t_q = -value.q_dot * (s * sine.jacobian + c * cosine.jacobian);
    }
    out.push_back(r);
  }
  return out;
}

// L(y)^T x = M(x) y for the body rate matrix L (euler_parameters.h).
Matrix4d TransposedRateMatrixApplied(const Vector3d& x) {
  Matrix4d m;
  m(0, 0) = 0.0;
  m.block<1, 3>(0, 1) = -x.transpose();
  m.block<3, 1>(1, 0) = x;
  m.block<3, 3>(1, 1) = -Skew(x);
  return m;
}

}  // namespace

int SpatialSystem::ConstraintCurvature(double t, const VectorXd& q, const VectorXd& w, MatrixXd* curvature) const {
  const int n = num_coordinates();
  curvature->setZero(n, n);
  for (int i = 0; i < static_cast<int>(model_.bodies.size()); ++i) {
    curvature->block<4, 4>(kBlock * i + 3, kBlock * i + 3).diagonal().array() += 2.0 * kNormRowScale * w[i];
  }
  for (const RowWithHessian& r : RowsWithHessians(*this, t, q)) {
    pair::ScatterHessian(r.equation.hessian, w[r.row], r.body_a, r.body_b, curvature);
  }
  return curvature->allFinite() ? 0 : 1;
}

int SpatialSystem::VelocityConstraintJacobian(double t, const VectorXd& q, const VectorXd& v,
                                              MatrixXd* jacobian) const {
  jacobian->setZero(num_rows_, num_coordinates());
  for (int i = 0; i < static_cast<int>(model_.bodies.size()); ++i) {
    jacobian->block<1, 4>(i, kBlock * i + 3) = 2.0 * kNormRowScale * v.segment<4>(kBlock * i + 3).transpose();
  }
  for (const RowWithHessian& r : RowsWithHessians(*this, t, q)) {
    const PairRow row = (r.equation.hessian * pair::PairRates(r.body_a, r.body_b, v)).transpose() + r.phi_t_q;
    pair::Scatter(row, r.body_a, r.body_b, jacobian->middleRows(r.row, 1));
  }
  return jacobian->allFinite() ? 0 : 1;
}

// A body's block of M(q) a is m a_r and (4 L(p)^T J L(p) + c p p^T) b with
// b = a_p and c = 4 tr(J) / 3. L is linear in p with L(p) b = -L(b) p and
// L(p)^T x = X(x) p (TransposedRateMatrixApplied), so
//   d(4 L(p)^T J L(p) b)/dp = 4 X(J L(p) b) - 4 L(p)^T J L(b),
//   d(c p p^T b)/dp = c ((p . b) I + p b^T).
int SpatialSystem::MassTimesAccelerationJacobian(const VectorXd& q, const VectorXd& a, MatrixXd* jacobian) const {
  const int n = num_coordinates();
  jacobian->setZero(n, n);
  for (size_t i = 0; i < model_.bodies.size(); ++i) {
    const int at = kBlock * static_cast<int>(i) + 3;
    const Matrix3d& inertia = model_.bodies[i].inertia_kg_m2;
    const Vector4d p = q.segment<4>(at), b = a.segment<4>(at);
    const Matrix34d l = BodyRateMatrix(p);
    const double along_p = 4.0 * inertia.trace() / 3.0;
    jacobian->block<4, 4>(at, at) = 4.0 * TransposedRateMatrixApplied(inertia * l * b) -
                                    4.0 * l.transpose() * inertia * BodyRateMatrix(b) +
                                    along_p * (p.dot(b) * Matrix4d::Identity() + p * b.transpose());
  }
  return jacobian->allFinite() ? 0 : 1;
}

bool SpatialSystem::has_force_elements() const {
  return !model_.springs.empty() || !model_.point_forces.empty() || !model_.torques.empty() ||
         !model_.rotational_springs.empty() || !model_.bushings.empty();
}

int SpatialSystem::ForceJacobians(double t, const VectorXd& q, const VectorXd& v, MatrixXd* q_q,
                                  MatrixXd* q_v) const {
  const int n = num_coordinates();
  q_q->setZero(n, n);
  q_v->setZero(n, n);
  // 8 L(p')^T J L(p') p: linear in p; in p', with L(y) p = -L(p) y,
  // 8 M(J L(p') p) - 8 L(p')^T J L(p).
  for (size_t i = 0; i < model_.bodies.size(); ++i) {
    const int at = kBlock * static_cast<int>(i) + 3;
    const Matrix3d& inertia = model_.bodies[i].inertia_kg_m2;
    const Vector4d p = q.segment<4>(at), p_dot = v.segment<4>(at);
    const Matrix34d l = BodyRateMatrix(p), l_dot = BodyRateMatrix(p_dot);
    q_q->block<4, 4>(at, at) = 8.0 * l_dot.transpose() * inertia * l_dot;
    q_v->block<4, 4>(at, at) =
        8.0 * TransposedRateMatrixApplied(inertia * l_dot * p) - 8.0 * l_dot.transpose() * inertia * l;
  }
  if (!has_force_elements()) return 0;
  return AddElementJacobians(model_, t, q, v, continue_past_bounds_, &spring_angles_, q_q, q_v);
}

void SpatialSystem::DerivativePattern(Pattern* coupling, Pattern* rows) const {
  const int n = num_coordinates();
  coupling->setConstant(n, n, false);
  rows->setConstant(num_rows_, n, false);
  auto couple = [&](int a, int b) {
    for (int i : {a, b}) {
      for (int k : {a, b}) {
        if (i != kGround && k != kGround) coupling->block<kBlock, kBlock>(kBlock * i, kBlock * k).setConstant(true);
      }
    }
  };
  auto row_on = [&](int row, int a, int b) {
    for (int body : {a, b}) {
      if (body != kGround) rows->block<1, kBlock>(row, kBlock * body).setConstant(true);
    }
  };
  for (int i = 0; i < static_cast<int>(model_.bodies.size()); ++i) {
    couple(i, i);
    row_on(i, i, i);
  }
  for (size_t j = 0; j < model_.joints.size(); ++j) {
    const Joint& joint = model_.joints[j];
    couple(joint.a.body, joint.b.body);
    for (int k = 0; k < JointEquationCount(joint.kind); ++k) row_on(joint_row_[j] + k, joint.a.body, joint.b.body);
  }
  for (size_t d = 0; d < model_.drivers.size(); ++d) {
    const Joint& joint = model_.joints[static_cast<size_t>(model_.drivers[d].joint)];
    row_on(driver_row_[d], joint.a.body, joint.b.body);
  }
  for (const SpringDamper& s : model_.springs) couple(s.a.body, s.b.body);
  for (const Bushing& b : model_.bushings) couple(b.a.body, b.b.body);
}

}  // namespace mbopt::spatial
