// The state of a mechanism at one output instant, as the analyses report it
// to whoever computes outputs: coordinates, velocities, accelerations and the
// Lagrange multipliers (the generalized constraint reactions are
// -Phi_q^T lambda; for a revolute joint, rows (x, y) of lambda are the force
// that body a exerts on body b; for a driver row, -lambda is the torque (or
// force) the driver applies to body b).
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Dense>

#include "spec/analysis_outcome.h"
#include "worker/multibody/constrained_system.h"

namespace mbopt::multibody {

// Derivatives of a state with respect to one parameter.
struct StateSensitivity {
  Eigen::VectorXd q, v, a, lambda;
};

struct MotionSample {
  double t_s = 0.0;
  Eigen::VectorXd q, v, a;
  Eigen::VectorXd lambda;  // empty when not computed
  // One per parameter when the analysis carries sensitivities, else empty.
  std::vector<StateSensitivity> sensitivities;
  // Driven kinematics: the sign of det(Phi_q), which changes only through a
  // locking position (0 elsewhere).
  int branch_sign = 0;
};

// A system's parameter dependence for sensitivity analysis: the system
// rebuilt at p_k + step_k and p_k - step_k (same structure: coordinates,
// rows), and its exact derivative where there is one. The systems outlive
// the analysis.
struct ParameterPerturbation {
  const ConstrainedSystem* plus = nullptr;
  const ConstrainedSystem* minus = nullptr;
  double step = 0.0;
  double magnitude = 1.0;  // |p_k| (1 for p_k = 0): scales the sensitivities' absolute tolerances
  // When p_k enters only coefficients the equations are linear in: a system
  // whose mass matrix and applied forces are dM/dp_k and dQ/dp_k (the
  // constraints do not depend on p_k; parameter_derivatives.h). Null: the
  // equations' derivative in p_k is a central difference of plus and minus.
  const ConstrainedSystem* derivative = nullptr;
};

// Sees every output instant in turn; a failure stops the analysis.
using MotionCallback = std::function<spec::AnalysisFailure(const MotionSample&)>;

}  // namespace mbopt::multibody
