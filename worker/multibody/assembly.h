// Assembly of a mechanism at a time t: positions by damped Newton on the
// constraint equations (drivers at t, and every joint coordinate that has an
// initial value held at it), from the bodies' initial poses; then
// velocities from Phi_q v = -Phi_t with the initial joint rates held. The
// degrees of freedom are counted from the rank of the constraint Jacobian at
// the assembled configuration (column-pivoted QR), so redundant joints (a
// planar four-bar closed with one joint too many) are found and named.
// Failures are data: a loop that cannot close is a kAssembly failure naming
// the joint with the largest residual and the time.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "spec/analysis_outcome.h"
#include "worker/multibody/mechanism.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::multibody {

struct AssemblyOptions {
  // Residual of the constraint equations accepted as closed (m or rad):
  // far below any tolerance a simulation is asked for, far above round-off
  // of coordinates of order 1 m.
  double position_tolerance = 1e-11;
  int max_iterations = 50;
  // Relative threshold of the QR's diagonal below which a constraint row is
  // counted as redundant.
  double rank_tolerance = 1e-9;
  // Newton steps taken after convergence: sensitivities difference
  // assemblies of nearby designs, which needs positions closed to round-off,
  // not to the tolerance.
  int polish_iterations = 0;
  // Velocities restricted to v = T w (n x r), the minimum-norm w: flexible
  // links start with rigid-body velocities (each link's nodes move as one
  // rigid body), not with the minimum-norm node velocities. Null: v free.
  const Eigen::MatrixXd* velocity_basis = nullptr;
  // The analysis' deadline and cancel flag, checked at every Newton
  // iteration (null: none).
  const budget::AnalysisBudget* budget = nullptr;
};

struct Assembly {
  spec::AnalysisFailure failure;
  Eigen::VectorXd q, v;
  int degrees_of_freedom = 0;             // with the drivers: 0 for a driven mechanism
  std::vector<std::string> redundant;     // joints whose rows are redundant
  int newton_iterations = 0;
};

Assembly Assemble(const Mechanism& mechanism, double t_s, const AssemblyOptions& options = {});

// Newton on Phi(t, q) = 0 from `q` (square, independent rows: a driven
// mechanism with no free coordinate). Returns iterations used, or a failure.
spec::AnalysisFailure SolvePositions(const Mechanism& mechanism, double t_s, const AssemblyOptions& options,
                                     Eigen::VectorXd* q, int* iterations);

// The joint whose rows weigh most in the direction in which Phi_q is
// (nearly) singular: where a mechanism locks.
std::string LockingJoint(const Mechanism& mechanism, const Eigen::MatrixXd& phi_q);

}  // namespace mbopt::multibody
