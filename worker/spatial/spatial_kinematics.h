// Kinematic analysis of a fully driven spatial mechanism (every degree of
// freedom prescribed by a driver): at each output instant the positions by
// Newton on Phi(t, q) = 0, the velocities from Phi_q v = -Phi_t and the
// accelerations from Phi_q a = gamma; no time integration, no mass matrix.
// The spatial counterpart of worker/multibody/kinematic_analysis.h, on a
// SpatialSystem's equations (Euler parameters, their unit norms as rows).
//
// The branch the mechanism assembled in is kept: each instant's Newton
// starts from the previous one's motion extrapolated to second order, and
// the interval is halved where Newton does not converge, corrects the
// prediction by more than a small share of the mechanism's size, or lands
// where det(Phi_q) has the other sign (another assembly branch, or a
// locking position passed in between). A singular Phi_q (a dead centre, a
// lock-up) ends the analysis as a kAssembly failure naming the time.
//
// Redundant rows (a Jacobian of full column rank with more rows than
// coordinates) are solved in the least-squares sense: positions, velocities
// and accelerations are unique; the branch test is then skipped.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Dense>

#include "spec/analysis_outcome.h"
#include "worker/budget/analysis_budget.h"
#include "worker/multibody/motion.h"
#include "worker/spatial/spatial_assembly.h"
#include "worker/spatial/spatial_system.h"

namespace mbopt::spatial {

struct SpatialKinematicOptions {
  SpatialAssemblyOptions assembly;
  // Reciprocal condition number of Phi_q below which the mechanism counts as
  // locked (the scaled unit-norm rows included).
  double singular_rcond = 1e-12;
  int max_interval_halvings = 12;
  // Charged one step per position solve; also the deadline and cancel flag.
  // Null: no limit.
  budget::AnalysisBudget* budget = nullptr;
};

struct SpatialKinematicCounters {
  std::int64_t position_solves = 0;
  std::int64_t newton_iterations = 0;
};

// `q0` assembled at times_s.front() (AssembleSpatial, zero degrees of
// freedom); `times_s` ascending. Each instant's sample (q, v, a; no
// multipliers: see DriverMultipliers) goes to `at_instant`.
spec::AnalysisFailure RunSpatialKinematics(const SpatialSystem& system, const Eigen::VectorXd& q0,
                                           const std::vector<double>& times_s, const SpatialKinematicOptions& options,
                                           const multibody::MotionCallback& at_instant,
                                           SpatialKinematicCounters* counters);

// Inverse dynamics of a state with its accelerations: the multipliers of
// M a + Phi_q^T lambda = Q (least squares, minimum norm where rows are
// redundant). -lambda of a driver's row is the torque (angle) or force
// (slide) the driver applies to its joint's body b about or along frame a's
// z axis. Empty on a non-finite evaluation.
Eigen::VectorXd Multipliers(const SpatialSystem& system, double t_s, const Eigen::VectorXd& q,
                            const Eigen::VectorXd& v, const Eigen::VectorXd& a);

}  // namespace mbopt::spatial
