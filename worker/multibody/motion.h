// The state of a mechanism at one output instant, as the analyses report it
// to whoever computes outputs: coordinates, velocities, accelerations and the
// Lagrange multipliers (the generalized constraint reactions are
// -Phi_q^T lambda; for a revolute joint, rows (x, y) of lambda are the force
// that body a exerts on body b; for a driver row, -lambda is the torque (or
// force) the driver applies to body b).
#pragma once

#include <functional>

#include <Eigen/Dense>

#include "spec/analysis_outcome.h"

namespace mbopt::multibody {

struct MotionSample {
  double t_s = 0.0;
  Eigen::VectorXd q, v, a;
  Eigen::VectorXd lambda;  // empty when not computed
};

// Sees every output instant in turn; a failure stops the analysis.
using MotionCallback = std::function<spec::AnalysisFailure(const MotionSample&)>;

}  // namespace mbopt::multibody
