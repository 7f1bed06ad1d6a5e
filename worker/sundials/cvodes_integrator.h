// CvodesIntegrator: an RAII wrapper over SUNDIALS CVODES (6.x) for one ODE
// system y' = f(t, y) of fixed size, with a dense direct linear solver or a
// caller-supplied solver of the Newton systems (CreateWithNewtonSolver).
//
// Owns the SUNContext, the CVODE memory, the state N_Vector, the dense matrix
// and the linear solver; nothing leaks on any path. Every SUNDIALS return code
// is checked; SUNDIALS' own error messages are captured (never printed) and
// end up in the returned status. No exception crosses the C callbacks: a
// callback that throws is reported as a failed integration.
//
// Outcomes of IntegrateTo:
//  - OK: *y holds the state at t_out.
//  - kAborted: the integrator gave up (too many steps, error test or
//    convergence failures, a callback returned an unrecoverable error, NaN);
//    the message says which and at what time. Callers that treat integrator
//    failure as data (an analysis result) convert this into their result enum.
//  - kDeadlineExceeded: the analysis budget's deadline passed; the message
//    is the budget's reason.
//  - kCancelled: the analysis budget's cancel flag went up.
//  - kInvalidArgument: misuse (t_out behind the current time, wrong size).
//
// Not thread-safe; one integrator per analysis. Units are the caller's.
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "spec/analysis_outcome.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::sundials {

struct CvodesOptions {
  enum class Method {
    kBdf,    // stiff problems: BDF + Newton + dense direct solver
    kAdams,  // non-stiff problems: Adams-Moulton + Newton + dense solver
  };
  Method method = Method::kBdf;
  // Newton with the dense linear solver (and the Jacobian, if given), or
  // fixed-point (functional) iteration without any linear solve: cheaper per
  // step for non-stiff problems with Adams.
  enum class Iteration { kNewton, kFixedPoint };
  Iteration iteration = Iteration::kNewton;
  double relative_tolerance = 1e-6;
  double absolute_tolerance = 1e-9;     // used when absolute_tolerances is empty
  Eigen::VectorXd absolute_tolerances;  // per state; empty: the scalar above
  // Budget of internal steps over the integrator's whole life (summed over
  // every IntegrateTo and Restart), not per call.
  std::int64_t max_steps = 100000;
  // The analysis' deadline and cancel flag, checked in every right-hand
  // side (null: none). Not owned; outlives the integrator.
  const budget::AnalysisBudget* budget = nullptr;
  double max_step_size = 0.0;      // 0: no limit
  double initial_step_size = 0.0;  // 0: CVODES' estimate

  absl::Status Validate(int num_states) const;
};

struct CvodesCounters {
  std::int64_t steps = 0;
  std::int64_t rhs_evaluations = 0;  // including those for finite-difference Jacobians
  std::int64_t jacobian_evaluations = 0;
  std::int64_t nonlinear_iterations = 0;
  std::int64_t nonlinear_convergence_failures = 0;
  std::int64_t error_test_failures = 0;
  std::int64_t restarts = 0;
};

class CvodesIntegrator {
 public:
  // y' = f(t, y): writes ydot (length N) from y (length N). Returns 0 on
  // success, > 0 for a recoverable error (CVODES retries with a smaller step),
  // < 0 for an unrecoverable one.
  using RhsFunction = std::function<int(double t, const double* y, double* ydot)>;
  // df/dy at (t, y) into `jacobian` (N x N, column-major, leading dimension
  // N, zeroed before the call). Same return convention as RhsFunction.
  using JacobianFunction =
      std::function<int(double t, const double* y, const double* ydot, double* jacobian)>;

  // Solves the Newton system (I - gamma J(t)) x = b of the step being taken
  // at time t, in place (b on entry, x on return; length N). The callee owns
  // its matrices and decides when to refactor; it sets *refactored when it
  // did (counted as a Jacobian evaluation). Any matrix close enough to
  // I - gamma J converges; an exact one converges in one iteration. Same
  // return convention as RhsFunction (> 0: CVODES retries with a smaller
  // step).
  using NewtonSolveFunction =
      std::function<int(double t, double gamma, double* b_then_x, bool* refactored)>;

  // Starts at (t0, y0). Without `jacobian` CVODES uses difference quotients.
  static absl::StatusOr<std::unique_ptr<CvodesIntegrator>> Create(int num_states, RhsFunction rhs,
                                                                  JacobianFunction jacobian,
                                                                  const CvodesOptions& options,
                                                                  double t0,
                                                                  const Eigen::VectorXd& y0);
  // When the Newton solver is handed a new (t, gamma):
  enum class NewtonRefresh {
    // Every Newton iteration gets the attempted step's own t and gamma: for
    // Jacobians that change quickly in time (a matrix-embedded solver;
    // CVODES' setup heuristics are off).
    kEveryIteration,
    // Only when CVODES' heuristics call for a linear-solver setup (a step
    // count, a gamma change of 30 %, a convergence failure); in between,
    // CVODES rescales the solution for the gamma change. Cheapest per step
    // for constant or slowly varying Jacobians.
    kCvodesSetups,
  };
  // The same with Newton iteration whose linear systems `newton_solve`
  // solves: no dense N x N matrix. For structured systems, e.g.
  // second-order ones where I - gamma J reduces to M + gamma C + gamma^2 K.
  // options.iteration must be kNewton.
  static absl::StatusOr<std::unique_ptr<CvodesIntegrator>> CreateWithNewtonSolver(
      int num_states, RhsFunction rhs, NewtonSolveFunction newton_solve, NewtonRefresh refresh,
      const CvodesOptions& options, double t0, const Eigen::VectorXd& y0);

  ~CvodesIntegrator();
  CvodesIntegrator(const CvodesIntegrator&) = delete;
  CvodesIntegrator& operator=(const CvodesIntegrator&) = delete;

  // Advances to t_out >= current time and writes y(t_out). With a stop time
  // set and t_out beyond it, stops there instead (see current_time()).
  absl::Status IntegrateTo(double t_out, Eigen::VectorXd* y);

  // The integrator never steps past t_stop (it would otherwise overshoot and
  // interpolate back). Cleared by CVODES once reached.
  absl::Status SetStopTime(double t_stop);

  // Restarts at (t, y) with a fresh history (order 1, new step size): the
  // way to cross a kink of f in time without losing accuracy. Counters and
  // the step budget carry over.
  absl::Status Restart(double t, const Eigen::VectorXd& y);

  double current_time() const { return t_; }
  int num_states() const { return num_states_; }
  // Counters summed over the whole life, across restarts.
  CvodesCounters counters() const;

 private:
  struct Sundials;  // the C handles
  CvodesIntegrator(int num_states, RhsFunction rhs, JacobianFunction jacobian,
                   const CvodesOptions& options);
  absl::Status Init(double t0, const Eigen::VectorXd& y0);
  absl::Status InitLinearSolver();
  absl::Status Check(int flag, const char* call);
  void AccumulateCounters();
  friend struct CvodesCallbacks;  // the C callbacks, in the .cc

  int num_states_;
  RhsFunction rhs_;
  JacobianFunction jacobian_;
  NewtonSolveFunction newton_solve_;
  NewtonRefresh newton_refresh_ = NewtonRefresh::kEveryIteration;
  double setup_t_ = 0.0, setup_gamma_ = 0.0;  // of the last CVODES setup (kCvodesSetups)
  std::int64_t newton_refactorizations_ = 0;  // by newton_solve_, over the whole life
  CvodesOptions options_;
  std::unique_ptr<Sundials> sundials_;
  double t_ = 0.0;
  std::string last_sundials_message_;
  std::string callback_failure_;
  spec::AnalysisFailure budget_failure_;  // why the budget stopped the last IntegrateTo
  double stop_time_ = 0.0;
  bool stop_time_set_ = false;
  CvodesCounters carried_;  // counters of histories ended by Restart
};

}  // namespace mbopt::sundials
