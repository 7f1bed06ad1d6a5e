// The residual of the stabilized index-2 (GGL) equations of motion that the
// forward-dynamics integrator solves (forward_dynamics.h), and its Newton
// matrix. Unknowns y = (q, v, lambda, mu), sizes (n, n, m, m):
//
//   F = [ q' - v + Phi_q^T mu ; M v' + Phi_q^T lambda - Q ; Phi ; Phi_q v + Phi_t ]
//
// Pure numerics on a ConstrainedSystem (no SUNDIALS): the integrator's
// callbacks call these, and the tests compare the Newton matrix with
// difference quotients of the residual.
#pragma once

#include <Eigen/Dense>

#include "worker/multibody/constrained_system.h"

namespace mbopt::multibody {

// The matrices one evaluation fills; reused between evaluations.
struct GglWorkspace {
  Eigen::MatrixXd mass, phi_q;
  Eigen::VectorXd forces, phi, phi_t;
  Eigen::MatrixXd force_q, force_v, curvature_mu, curvature_lambda, velocity_q, mass_q;
};

// F(t, y, y') into `r` (size 2n + 2m); the SUNDIALS callback contract: 0 ok,
// > 0 recoverable, < 0 fatal. Evaluated with the system's validity bounds
// continued (ContinuedPastBounds): the integrator's trial states may cross
// them.
int GglResidual(const ConstrainedSystem& s, double t, const Eigen::Ref<const Eigen::VectorXd>& y,
                const Eigen::Ref<const Eigen::VectorXd>& y_dot, GglWorkspace* work, Eigen::Ref<Eigen::VectorXd> r);

// dF/dy + cj dF/dy' at (t, y, y') from the system's analytic derivatives:
// the caller checks has_analytic_derivatives(). F is linear in y'; y' enters
// only through d(M(q) v')/dq (MassTimesAccelerationJacobian), zero for a
// constant mass matrix.
int GglNewtonMatrix(const ConstrainedSystem& s, double t, double cj, const Eigen::Ref<const Eigen::VectorXd>& y,
                    const Eigen::Ref<const Eigen::VectorXd>& y_dot, GglWorkspace* work, Eigen::MatrixXd* newton);

// dF/dy times `direction` at (t, y, y'), for a system without an exact
// state Jacobian (has_exact_state_jacobian(); forward sensitivities: forward_dynamics.h). The parts of F
// linear in (v, lambda, mu) and the position rows are exact (with `phi_q`,
// Phi_q at y's q); the rest, how M v', Q, Phi_q^T lambda, Phi_q^T mu and
// Phi_q v + Phi_t change with (q, v), is a central difference of the
// residual along the direction's (q, v) part, scaled so that no component
// moves by more than 1e-4 (1 + |y_i|).
int GglStateDirectionalDerivative(const ConstrainedSystem& s, double t, const Eigen::Ref<const Eigen::VectorXd>& y,
                                  const Eigen::Ref<const Eigen::VectorXd>& y_dot,
                                  const Eigen::Ref<const Eigen::VectorXd>& direction, const Eigen::MatrixXd& phi_q,
                                  GglWorkspace* work, Eigen::Ref<Eigen::VectorXd> out);

// Which entries of the Newton matrix can be non-zero (size x size), from the
// system's DerivativePattern.
ConstrainedSystem::Pattern GglNewtonPattern(const ConstrainedSystem& s);

}  // namespace mbopt::multibody
