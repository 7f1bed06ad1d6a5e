// Forward dynamics of a constrained system on the non-stiff path: an
// explicit embedded Runge-Kutta pair (SUNDIALS ARKODE's ERKStep) on the
// index-1 form, with the state projected back onto the constraints after
// every accepted step.
//
// The state is y = (q, v) and y' = (v, a), the accelerations from the
// augmented system [M Phi_q^T; Phi_q 0] [a; lambda] = [Q; gamma]. That ODE
// keeps Phi and Phi_q v + Phi_t constant only to the truncation error, so
// the drift grows along the motion; after each accepted step q is moved
// onto Phi(t, q) = 0 by Gauss-Newton with the minimum-norm correction
// (-Phi_q^T (Phi_q Phi_q^T)^-1 Phi) and v onto Phi_q v + Phi_t = 0 by the
// same projector, and the integrator continues from the projected state.
//
// An explicit method's step is bounded by its stability region, not only by
// its accuracy: on a stiff system (a stiff spring, a flexible link) the step
// collapses and the step budget ends the analysis with a named failure.
// Sensitivities are not carried (IntegrateForward refuses them here).
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "spec/analysis_outcome.h"
#include "worker/multibody/constrained_system.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/motion.h"

namespace mbopt::multibody {

// As IntegrateForward with options.method == kExplicitRungeKutta (which
// calls this): from (t0, q0, v0), consistent with the constraints, to every
// instant of `times_s`. Every step ends at most at the next instant, so the
// samples' q and v are the integrator's projected state there; a and lambda
// are the augmented system's at that state.
spec::AnalysisFailure IntegrateForwardExplicit(const ConstrainedSystem& system, double t0_s,
                                               const Eigen::VectorXd& q0, const Eigen::VectorXd& v0,
                                               const std::vector<double>& times_s,
                                               const ForwardDynamicsOptions& options,
                                               const MotionCallback& at_instant, ForwardDynamicsCounters* counters);

}  // namespace mbopt::multibody
