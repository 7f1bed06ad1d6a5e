// Forward dynamics of a constrained system (DOF > 0) with SUNDIALS IDAS, in
// the stabilized index-2 form of Gear, Gupta and Leimkuhler (GGL), as in
// SUNDIALS' own slider-crank example: unknowns y = (q, v, lambda, mu) and
//
//   q' - v + Phi_q^T mu = 0        (mu keeps the positions on Phi = 0)
//   M v' + Phi_q^T lambda - Q = 0
//   Phi(t, q) = 0
//   Phi_q v + Phi_t = 0
//
// so both position and velocity constraints hold along the solution, without
// a stabilization parameter to tune. q and v are differential, lambda and mu
// algebraic and left out of the error test (IDASetSuppressAlg): their
// accuracy follows from q and v. Consistent initial values come from the
// caller's assembled (q0, v0): a0 and lambda0 from the augmented system
// [M Phi_q^T; Phi_q 0] [a; lambda] = [Q; gamma], mu0 = 0.
//
// Newton's matrix comes from the system's analytic derivatives when it has
// them (ggl_residual.h; dense LU or KLU, ForwardDynamicsOptions), else from
// IDAS's difference quotients.
//
// Failures are data: IDAS giving up (error-test or convergence failures, the
// step budget), a singular augmented matrix at the start (a lock-up), and the
// wall-time limit end the analysis with their kind and the time.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Dense>

#include "spec/analysis_outcome.h"
#include "spec/scene.h"
#include "worker/budget/analysis_budget.h"
#include "worker/multibody/constrained_system.h"
#include "worker/multibody/motion.h"

namespace mbopt::multibody {

struct ForwardDynamicsOptions {
  double relative_tolerance = 1e-6;
  double absolute_tolerance = 1e-9;  // on q (m, rad) and v (m/s, rad/s)
  long max_steps = 100000;           // over the whole integration
  // The analysis' deadline and cancel flag, checked in every residual and
  // Newton matrix (null: none).
  const budget::AnalysisBudget* budget = nullptr;
  double max_step_size = 0.0;        // 0: no limit
  // The Newton systems' linear solver, for a system with analytic
  // derivatives (others get dense LU of difference quotients): dense LU,
  // or KLU on the sparse Newton matrix whose pattern the system declares
  // (ConstrainedSystem::DerivativePattern); automatic picks KLU from
  // kSparseFromUnknowns unknowns (2n + 2m) up: measured 1.9x faster than
  // dense LU at 44 unknowns and 2.8-8.8x at 104-404 (docs/benchmarks.md);
  // below, dense.
  enum class LinearSolver { kAutomatic, kDense, kSparse };
  LinearSolver linear_solver = LinearSolver::kAutomatic;
  static constexpr int kSparseFromUnknowns = 40;

  // The integrator: IDAS's variable-order BDF on the stabilized index-2
  // form (above), or an explicit Runge-Kutta pair on the index-1 form with
  // projection onto the constraints (explicit_dynamics.h) for non-stiff
  // motions, where it takes fewer, cheaper steps. The explicit path carries
  // no sensitivities.
  enum class Method { kImplicitBdf, kExplicitRungeKutta };
  Method method = Method::kImplicitBdf;
  // The explicit path's embedded pair (ARKODE's tables of those names).
  enum class ExplicitPair { kDormandPrince54, kVerner65, kFehlberg87 };
  ExplicitPair explicit_pair = ExplicitPair::kVerner65;
  // The explicit path's outputs: every step ending at most at the next
  // instant (true: a floor of a step or two per output interval), or from
  // ERKStep's degree-5 Hermite interpolant over the step that spans each
  // instant, projected (false). Measured on the work-precision bench
  // (docs/benchmarks.md): interpolated outputs took 4-66 % fewer steps but
  // were 2-500x less accurate at the same tolerance, and no faster at equal
  // error (slower on the ten-body chain).
  bool explicit_stop_at_instants = true;

  // A scene's integrator settings (tolerances, step budget) within `budget`.
  static ForwardDynamicsOptions Of(const spec::IntegratorSettings& integrator, const budget::AnalysisBudget* budget) {
    ForwardDynamicsOptions options;
    options.relative_tolerance = integrator.relative_tolerance;
    options.absolute_tolerance = integrator.absolute_tolerance;
    options.max_steps = integrator.max_steps;
    options.budget = budget;
    if (integrator.method == spec::IntegratorMethod::kExplicitRungeKutta) {
      options.method = Method::kExplicitRungeKutta;
    }
    return options;
  }
};

struct ForwardDynamicsCounters {
  std::int64_t steps = 0;
  std::int64_t residual_evaluations = 0;
  std::int64_t jacobian_evaluations = 0;
  // Residuals spent on difference-quotient Newton matrices (none when the
  // system has analytic derivatives).
  std::int64_t jacobian_residual_evaluations = 0;
  bool sparse_linear_solver = false;  // KLU, else dense LU
  std::int64_t nonlinear_iterations = 0;
  std::int64_t error_test_failures = 0;
  std::int64_t convergence_failures = 0;
  // Largest |Phi| and |Phi_q v + Phi_t| at the output instants: the drift
  // the GGL form keeps at the integration tolerance.
  double max_position_drift = 0.0;
  double max_velocity_drift = 0.0;
  // When IDAS's step growth was held to 1.5 after the doubling-rejection
  // cycle (forward_dynamics.cc, LimitGrowthIfTrapped); negative: never.
  double step_growth_limited_from_s = -1.0;
};

// Forward sensitivities with respect to parameters (IDAS's forward
// sensitivity module, staggered corrector, sensitivities in the error test
// with absolute tolerances divided by each parameter's magnitude). The
// sensitivity residuals F_y s + F_y' s' + F_p take F_y from the system's
// analytic derivatives where they are its exact state Jacobian
// (has_exact_state_jacobian()), or else F_y s from a central
// difference of the residual along s (GglStateDirectionalDerivative), and
// F_p from the parameter's derivative model, else from central differences
// of the residual alone between the systems rebuilt at p_k +- step_k
// (ParameterPerturbation, parameter_derivatives.h); the initial
// sensitivities of lambda and the accelerations are central differences of
// the consistent start along (q0_k, v0_k, e_k).
struct ForwardSensitivityInput {
  std::vector<ParameterPerturbation> parameters;
  std::vector<Eigen::VectorXd> q0, v0;  // dq0/dp_k, dv0/dp_k of the assembled start
};

// From (t0, q0, v0), consistent with the constraints, to every instant of
// `times_s` (ascending, >= t0); `at_instant` sees (t, q, v, a, lambda) and,
// with `sensitivities`, their derivatives per parameter.
spec::AnalysisFailure IntegrateForward(const ConstrainedSystem& system, double t0_s, const Eigen::VectorXd& q0,
                                       const Eigen::VectorXd& v0, const std::vector<double>& times_s,
                                       const ForwardDynamicsOptions& options, const MotionCallback& at_instant,
                                       ForwardDynamicsCounters* counters,
                                       const ForwardSensitivityInput* sensitivities = nullptr);

}  // namespace mbopt::multibody
