// Derivatives of a driven mechanism's state (no degree of freedom left) with
// respect to one parameter, by differentiating the equations the kinematic
// analysis solves at an instant, in turn:
//
//   Phi(t, q; p) = 0                       -> Phi_q dq = -dPhi
//   Phi_q v + Phi_t = 0                    -> Phi_q dv = -d(Phi_q v + Phi_t)
//   Phi_q a - gamma = 0                    -> Phi_q da = -d(Phi_q a - gamma)
//   Phi_q^T lambda - Q + M a = 0           -> Phi_q^T dlambda = -d(Phi_q^T lambda - Q + M a)
//
// where each right-hand side d(...) is the derivative along the parameter
// with the unknowns solved so far moving with it and the current unknown
// held: a central difference of the equations between the systems rebuilt
// at p +- step (ParameterPerturbation). One LU of Phi_q (and of Phi_q^T)
// per instant, shared by every parameter; no position solve is repeated.
#pragma once

#include <vector>

#include "worker/multibody/constrained_system.h"
#include "worker/multibody/motion.h"

namespace mbopt::multibody {

// `sample` as the kinematic analysis reports it (lambda empty: no
// multipliers wanted); one derivative per parameter into `out`. Returns
// false if an equation is not finite or Phi_q is not square.
bool KinematicStateSensitivities(const ConstrainedSystem& system, const std::vector<ParameterPerturbation>& parameters,
                                 const MotionSample& sample, std::vector<StateSensitivity>* out);

}  // namespace mbopt::multibody
