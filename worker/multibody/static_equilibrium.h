// Static (quasi-static) equilibrium of a constrained system at each output
// instant: the coordinates q and multipliers lambda with
//
//   Q(t, q, 0) - Phi_q(t, q)^T lambda = 0     (n equations: forces balance)
//   Phi(t, q) = 0                             (m constraints, drivers at t)
//
// solved by SUNDIALS KINSOL (Newton with a line search, the Jacobian by
// difference quotients), each instant started from the previous one's
// solution. The motion is taken as infinitely slow: drivers, moving inputs
// and time-varying loads act with their values at t, inertia and damping not
// at all, and the reported states have zero velocities and accelerations
// (a scene analysed statically may not ask for rates, accelerations or
// kinetic energy; the scene loader refuses them).
//
// An equilibrium that is not stable (the tangent stiffness reduced to the
// free directions, N^T K N with N spanning the null space of Phi_q, has a
// negative eigenvalue: an inverted pendulum) is a failed analysis naming the
// time, because a mechanism would move away from it. Non-conservative loads
// are judged by the symmetric part of K. A Newton failure (no equilibrium
// near the start, a singular Jacobian at a dead centre) is a kAssembly
// failure naming the time and KINSOL's reason.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Dense>

#include "spec/analysis_outcome.h"
#include "worker/multibody/constrained_system.h"
#include "worker/multibody/motion.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::multibody {

struct StaticOptions {
  // Converged when every constraint residual is below this (m or rad), or
  // below its row's round-off floor (100 eps |Phi_q row| |q|: a spatial
  // body's Euler-parameter norm row is scaled by 1e6) if that is higher, and
  // every force residual below it times the force scale (the largest applied
  // force at the start, at least 1 N), or below its row's round-off floor
  // (100 eps K_ii |q|, from the stiffness at the start) if that is higher.
  double tolerance = 1e-10;
  int max_iterations = 200;  // Newton iterations per instant
  // Relative size of the most negative reduced stiffness eigenvalue (to the
  // largest in magnitude) that still counts as neutral, not unstable.
  double stability_tolerance = 1e-8;
  // How the coordinates group into bodies, for the round-off floors: each
  // body's first `translations_per_body` coordinates are translations (m),
  // the rest of its `coordinates_per_body` describe its rotation. Planar:
  // (x, y, theta), 3 and 2; spatial: (r, Euler parameters), 7 and 3. The
  // translation rows of a body share one floor, its rotation rows another.
  int coordinates_per_body = 3;
  int translations_per_body = 2;
  // KINSOL's Newton matrix and the stiffness (round-off floors, stability
  // check) from the system's analytic derivatives (EquilibriumJacobian)
  // where they are its exact state Jacobian; false, or a system without
  // one: difference quotients.
  bool analytic_newton_matrix = true;
  // Charged one step per instant and per continuation step; also the
  // deadline and cancel flag. Null: no limit.
  budget::AnalysisBudget* budget = nullptr;
};

struct StaticCounters {
  std::int64_t position_solves = 0;      // one per instant
  std::int64_t newton_iterations = 0;
  std::int64_t residual_evaluations = 0;  // KINSOL's, Jacobian differences included
  std::int64_t newton_matrices = 0;       // analytic ones (none when differenced)
};

// dG/d(q, lambda) of the equilibrium equations G = (Q(t, q, 0) - Phi_q^T
// lambda, Phi(t, q)) from the system's analytic derivatives:
//
//   [Q_q - (Phi_q^T lambda)_q   -Phi_q^T]
//   [Phi_q                        0     ]
//
// False where the system has no exact state Jacobian
// (has_exact_state_jacobian) or a derivative fails.
bool EquilibriumJacobian(const ConstrainedSystem& system, double t, const Eigen::VectorXd& q,
                         const Eigen::VectorXd& lambda, Eigen::MatrixXd* jacobian);

// The derivatives of an equilibrium (q, lambda) of `sample` (as
// RunStaticEquilibrium reports it) with respect to each parameter, by the
// implicit function theorem on G(q, lambda; p) = 0:
//
//   [Q_q - (Phi_q^T lambda)_q   -Phi_q^T] [dq/dp      ]     [dG/dp]
//   [Phi_q                        0     ] [dlambda/dp ] = - [     ]
//
// the matrix from the system's analytic derivatives (velocities zero), one
// LU for every parameter; dG/dp from parameter_derivatives.h. Velocities
// and accelerations stay zero. False when the system has no exact state
// Jacobian (has_exact_state_jacobian()) or the matrix is singular (a dead
// centre).
bool StaticStateSensitivities(const ConstrainedSystem& system, const std::vector<ParameterPerturbation>& parameters,
                              const MotionSample& sample, std::vector<StateSensitivity>* sensitivities);

// From (q0) assembled at times_s.front(); `times_s` ascending.
spec::AnalysisFailure RunStaticEquilibrium(const ConstrainedSystem& system, const Eigen::VectorXd& q0,
                                           const std::vector<double>& times_s, const StaticOptions& options,
                                           const MotionCallback& at_instant, StaticCounters* counters);

}  // namespace mbopt::multibody
