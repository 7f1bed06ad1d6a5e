// Kinematic analysis of a driven mechanism (no degree of freedom left once
// driven): at each output instant the positions by Newton on Phi(t, q) = 0
// (started from the previous instant's motion extrapolated to second order,
// with the interval halved where Newton does not converge), the velocities
// from Phi_q v = -Phi_t and the accelerations from Phi_q a = gamma: no time
// integration, no mass matrix. With inverse dynamics, also the multipliers
// from Phi_q^T lambda = Q - M a (joint reactions, driver efforts).
//
// A singular constraint Jacobian (a dead-centre position, a lock-up) or a
// loop that cannot close ends the analysis as a kAssembly failure naming the
// joint and the time.
#pragma once

#include <cstdint>
#include <vector>

#include "worker/multibody/assembly.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/motion.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::multibody {

struct KinematicOptions {
  AssemblyOptions assembly;
  bool inverse_dynamics = false;
  // Reciprocal condition number of Phi_q below which the mechanism counts
  // as locked: round-off of the solved velocities then exceeds 1e-6 of them.
  double singular_rcond = 1e-10;
  int max_interval_halvings = 10;
  // Charged one step per position solve (instants and halved intervals
  // alike); also the deadline and cancel flag. Null: no limit.
  budget::AnalysisBudget* budget = nullptr;
};

struct KinematicCounters {
  std::int64_t position_solves = 0;
  std::int64_t newton_iterations = 0;
};

// `q0` assembled at times_s.front() (Assemble). `times_s` ascending.
spec::AnalysisFailure RunKinematics(const Mechanism& mechanism, const Eigen::VectorXd& q0,
                                    const std::vector<double>& times_s, const KinematicOptions& options,
                                    const MotionCallback& at_instant, KinematicCounters* counters);

// The driven motion at t_s solved from `near`, a sample of the same driven
// mechanism close in time (from RunKinematics or from this function): for
// callers that need the motion at instants of their own choosing (the
// floating-frame elastodynamics at its integrator's steps). The same
// predictor, interval halving and failures as RunKinematics between two
// instants; no multipliers.
spec::AnalysisFailure SolveMotionNear(const Mechanism& mechanism, const MotionSample& near, double t_s,
                                      const KinematicOptions& options, MotionSample* out,
                                      KinematicCounters* counters);

}  // namespace mbopt::multibody
