#include "worker/multibody/ggl_residual.h"

#include <algorithm>
#include <cmath>

namespace mbopt::multibody {

using Eigen::VectorXd;

int GglResidual(const ConstrainedSystem& s, double t, const Eigen::Ref<const VectorXd>& y,
                const Eigen::Ref<const VectorXd>& y_dot, GglWorkspace* w, Eigen::Ref<VectorXd> r) {
  const int n = s.num_coordinates(), m = s.num_constraints();
  const VectorXd q = y.head(n), v = y.segment(n, n);
  // Trial states past a validity bound stay finite; the bound's root
  // function (forward_dynamics.cc) ends the integration where the motion
  // crosses it.
  const ContinuedPastBounds continued(s);
  int flag = s.MassMatrix(q, &w->mass);
  if (flag == 0) flag = s.AppliedForces(t, q, v, &w->forces);
  if (flag == 0 && m > 0) flag = s.ConstraintJacobian(t, q, &w->phi_q);
  if (flag == 0 && m > 0) flag = s.Constraints(t, q, &w->phi);
  if (flag == 0 && m > 0) flag = s.ConstraintTimeDerivative(t, q, &w->phi_t);
  if (flag != 0) return flag;
  r.head(n) = y_dot.head(n) - v;
  r.segment(n, n) = w->mass * y_dot.segment(n, n) - w->forces;
  if (m > 0) {
    r.head(n) += w->phi_q.transpose() * y.segment(2 * n + m, m);
    r.segment(n, n) += w->phi_q.transpose() * y.segment(2 * n, m);
    r.segment(2 * n, m) = w->phi;
    r.segment(2 * n + m, m) = w->phi_q * v + w->phi_t;
  }
  return r.allFinite() ? 0 : 1;
}

// In blocks of rows (F_q, F_v, Phi, Phi_q v + Phi_t) and columns
// (q, v, lambda, mu):
//
//   [ cj I + (Phi_q^T mu)_q     -I            0        Phi_q^T ]
//   [ (M v')_q + (Phi_q^T lambda)_q - Q_q   cj M - Q_v    Phi_q^T  0 ]
//   [ Phi_q                      0             0        0       ]
//   [ (Phi_q v + Phi_t)_q        Phi_q         0        0       ]
int GglNewtonMatrix(const ConstrainedSystem& s, double t, double cj, const Eigen::Ref<const VectorXd>& y,
                    const Eigen::Ref<const VectorXd>& y_dot, GglWorkspace* w, Eigen::MatrixXd* j) {
  const int n = s.num_coordinates(), m = s.num_constraints(), size = 2 * n + 2 * m;
  const VectorXd q = y.head(n), v = y.segment(n, n);
  const ContinuedPastBounds continued(s);
  int flag = s.MassMatrix(q, &w->mass);
  if (flag == 0) flag = s.ForceJacobians(t, q, v, &w->force_q, &w->force_v);
  if (flag == 0) flag = s.MassTimesAccelerationJacobian(q, y_dot.segment(n, n), &w->mass_q);
  if (flag == 0 && m > 0) flag = s.ConstraintJacobian(t, q, &w->phi_q);
  if (flag == 0 && m > 0) flag = s.ConstraintCurvature(t, q, y.segment(2 * n + m, m), &w->curvature_mu);
  if (flag == 0 && m > 0) flag = s.ConstraintCurvature(t, q, y.segment(2 * n, m), &w->curvature_lambda);
  if (flag == 0 && m > 0) flag = s.VelocityConstraintJacobian(t, q, v, &w->velocity_q);
  if (flag != 0) return flag;
  j->setZero(size, size);
  j->topLeftCorner(n, n).diagonal().setConstant(cj);
  j->block(0, n, n, n).diagonal().setConstant(-1.0);
  j->block(n, 0, n, n) = w->mass_q - w->force_q;
  j->block(n, n, n, n) = cj * w->mass - w->force_v;
  if (m > 0) {
    j->topLeftCorner(n, n) += w->curvature_mu;
    j->block(0, 2 * n + m, n, m) = w->phi_q.transpose();
    j->block(n, 0, n, n) += w->curvature_lambda;
    j->block(n, 2 * n, n, m) = w->phi_q.transpose();
    j->block(2 * n, 0, m, n) = w->phi_q;
    j->block(2 * n + m, 0, m, n) = w->velocity_q;
    j->block(2 * n + m, n, m, n) = w->phi_q;
  }
  return j->allFinite() ? 0 : 1;
}

int GglStateDirectionalDerivative(const ConstrainedSystem& s, double t, const Eigen::Ref<const VectorXd>& y,
                                  const Eigen::Ref<const VectorXd>& y_dot, const Eigen::Ref<const VectorXd>& direction,
                                  const Eigen::MatrixXd& phi_q, GglWorkspace* w, Eigen::Ref<VectorXd> out) {
  const int n = s.num_coordinates(), m = s.num_constraints(), size = 2 * n + 2 * m;
  // Relative size of the difference's step: its truncation error is about
  // its square. Smaller steps carried the residual's round-off (eps over
  // the step) into the sensitivities' corrector, which then failed on the
  // spatial governor part-way at rtol 1e-10 (1e-6 and 1e-5; 1e-6 already
  // at 1e-9); 1e-4 integrates it at 1e-10.
  constexpr double kRelativeStep = 1e-4;
  double largest = 0.0;
  for (int i = 0; i < 2 * n; ++i) largest = std::max(largest, std::abs(direction[i]) / (1.0 + std::abs(y[i])));
  out.setZero();
  if (largest > 0.0) {
    const double e = kRelativeStep / largest;
    VectorXd moved = y, plus(size), minus(size);
    moved.head(2 * n) += e * direction.head(2 * n);
    if (int flag = GglResidual(s, t, moved, y_dot, w, plus); flag != 0) return flag;
    moved.head(2 * n) = y.head(2 * n) - e * direction.head(2 * n);
    if (int flag = GglResidual(s, t, moved, y_dot, w, minus); flag != 0) return flag;
    out = (plus - minus) / (2.0 * e);
  }
  if (m > 0) {
    out.head(n) += phi_q.transpose() * direction.segment(2 * n + m, m);
    out.segment(n, n) += phi_q.transpose() * direction.segment(2 * n, m);
    // Phi's rows are algebraic and tightly weighted: their exact
    // derivative, not the difference's round-off.
    out.segment(2 * n, m) = phi_q * direction.head(n);
  }
  return out.allFinite() ? 0 : 1;
}

ConstrainedSystem::Pattern GglNewtonPattern(const ConstrainedSystem& s) {
  const int n = s.num_coordinates(), m = s.num_constraints(), size = 2 * n + 2 * m;
  ConstrainedSystem::Pattern coupling, rows;
  s.DerivativePattern(&coupling, &rows);
  ConstrainedSystem::Pattern p = ConstrainedSystem::Pattern::Constant(size, size, false);
  const ConstrainedSystem::Pattern identity = Eigen::MatrixXd::Identity(n, n).array() != 0.0;
  p.topLeftCorner(n, n) = coupling || identity;
  p.block(0, n, n, n) = identity;
  p.block(n, 0, n, n) = coupling;
  p.block(n, n, n, n) = coupling || identity;
  if (m > 0) {
    p.block(0, 2 * n + m, n, m) = rows.transpose();
    p.block(n, 2 * n, n, m) = rows.transpose();
    p.block(2 * n, 0, m, n) = rows;
    p.block(2 * n + m, 0, m, n) = rows;
    p.block(2 * n + m, n, m, n) = rows;
  }
  return p;
}

}  // namespace mbopt::multibody
