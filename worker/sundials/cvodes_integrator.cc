#include "worker/sundials/cvodes_integrator.h"

#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "common/status_macros.h"
#include "worker/sundials/sundials_handles.h"

namespace mbopt::sundials {
namespace {

// The status that carries a budget's failure out of IntegrateTo;
// IntegratorFailure (integrator_failure.h) maps it back to its kind.
absl::Status BudgetStatus(const spec::AnalysisFailure& failure) {
  return failure.kind == spec::FailureKind::kCancelled ? absl::CancelledError(failure.reason)
                                                       : absl::DeadlineExceededError(failure.reason);
}

}  // namespace

// Declared in the order of creation, so destroyed CVODE memory first (it may
// still reference the solvers) and context last (sundials_handles.h).
struct CvodesIntegrator::Sundials {
  Context context;
  Vector y;
  Vector abstol;
  Matrix matrix;
  LinearSolver linear_solver;
  NonlinearSolver nonlinear_solver;
  Memory<&CVodeFree> cvode;
};

// The C side of the callbacks: each turns an exception or a non-finite value
// into a SUNDIALS return code and remembers why.
struct CvodesCallbacks {
  static int Rhs(realtype t, N_Vector y, N_Vector ydot, void* user_data) {
    auto* self = static_cast<CvodesIntegrator*>(user_data);
    if (self->options_.budget != nullptr && self->options_.budget->Exhausted()) {
      self->budget_failure_ = self->options_.budget->Check(t);
      if (!self->budget_failure_.ok()) return -1;
    }
    return GuardCallback(&self->callback_failure_, "right-hand side", [&]() -> int {
      const int flag = self->rhs_(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot));
      if (flag != 0) {
        if (flag < 0) {
          self->callback_failure_ = absl::StrFormat(
              "right-hand side reported an unrecoverable error (%d) at t = %.9g", flag, t);
        }
        return flag;
      }
      const double* out = N_VGetArrayPointer(ydot);
      for (int i = 0; i < self->num_states_; ++i) {
        if (!std::isfinite(out[i])) {
          self->callback_failure_ =
              absl::StrFormat("right-hand side is not finite at t = %.9g (state %d)", t, i);
          return -1;
        }
      }
      return 0;
    });
  }

  static int Jacobian(realtype t, N_Vector y, N_Vector fy, SUNMatrix jac, void* user_data, N_Vector,
                      N_Vector, N_Vector) {
    auto* self = static_cast<CvodesIntegrator*>(user_data);
    return GuardCallback(&self->callback_failure_, "Jacobian", [&]() -> int {
      SUNMatZero(jac);
      const int flag = self->jacobian_(t, N_VGetArrayPointer(y), N_VGetArrayPointer(fy),
                                       SUNDenseMatrix_Data(jac));
      if (flag < 0) {
        self->callback_failure_ =
            absl::StrFormat("Jacobian reported an unrecoverable error (%d) at t = %.9g", flag, t);
      }
      return flag;
    });
  }

  // The caller's Newton solver as a matrix-embedded SUNLinearSolver. CVODES
  // then skips its own setup heuristics and calls only Solve, once per
  // Newton iteration; t and gamma are those of the step being attempted.
  static SUNLinearSolver_Type NewtonType(SUNLinearSolver ls) {
    auto* self = static_cast<CvodesIntegrator*>(ls->content);
    // A direct solver gets CVODES' setup calls (through LinSys below) and no
    // iterative-solver tolerance bookkeeping in every solve.
    return self->newton_refresh_ == CvodesIntegrator::NewtonRefresh::kCvodesSetups
               ? SUNLINEARSOLVER_DIRECT
               : SUNLINEARSOLVER_MATRIX_EMBEDDED;
  }
  // CVODES' setup with the caller's solver: only remembers the (t, gamma)
  // that the following solves use. The caller's matrix is exact there.
  static int LinSys(realtype t, N_Vector, N_Vector, SUNMatrix, booleantype, booleantype* jcur,
                    realtype gamma, void* user_data, N_Vector, N_Vector, N_Vector) {
    auto* self = static_cast<CvodesIntegrator*>(user_data);
    self->setup_t_ = t;
    self->setup_gamma_ = gamma;
    *jcur = SUNTRUE;
    return 0;
  }
  static SUNLinearSolver_ID NewtonId(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
  static int NewtonSolve(SUNLinearSolver ls, SUNMatrix, N_Vector x, N_Vector b, realtype) {
    auto* self = static_cast<CvodesIntegrator*>(ls->content);
    double t = self->setup_t_, gamma = self->setup_gamma_;
    if (self->newton_refresh_ == CvodesIntegrator::NewtonRefresh::kEveryIteration &&
        (CVodeGetCurrentTime(self->sundials_->cvode.get(), &t) != CV_SUCCESS ||
         CVodeGetCurrentGamma(self->sundials_->cvode.get(), &gamma) != CV_SUCCESS)) {
      self->callback_failure_ = "Newton solver could not read the step's time and gamma";
      return SUNLS_PACKAGE_FAIL_UNREC;
    }
    return GuardCallback(&self->callback_failure_, "Newton solver", [&]() -> int {
      N_VScale(1.0, b, x);
      bool refactored = false;
      const int flag = self->newton_solve_(t, gamma, N_VGetArrayPointer(x), &refactored);
      if (refactored) ++self->newton_refactorizations_;
      if (flag == 0) return SUNLS_SUCCESS;
      if (flag > 0) return SUNLS_PACKAGE_FAIL_REC;
      self->callback_failure_ = absl::StrFormat(
          "Newton solver reported an unrecoverable error (%d) at t = %.9g", flag, t);
      return SUNLS_PACKAGE_FAIL_UNREC;
    }, SUNLS_PACKAGE_FAIL_UNREC);
  }
  // The content is the integrator, which outlives the solver; only the
  // shell is freed.
  static int NewtonFree(SUNLinearSolver ls) {
    ls->content = nullptr;
    SUNLinSolFreeEmpty(ls);
    return SUNLS_SUCCESS;
  }
};

absl::Status CvodesOptions::Validate(int num_states) const {
  if (num_states <= 0) {
    return absl::InvalidArgumentError(absl::StrCat("ODE size must be positive, got ", num_states));
  }
  if (!(relative_tolerance > 0.0) || !std::isfinite(relative_tolerance)) {
    return absl::InvalidArgumentError(
        absl::StrCat("relative_tolerance must be positive, got ", relative_tolerance));
  }
  if (absolute_tolerances.size() == 0) {
    if (!(absolute_tolerance > 0.0) || !std::isfinite(absolute_tolerance)) {
      return absl::InvalidArgumentError(
          absl::StrCat("absolute_tolerance must be positive, got ", absolute_tolerance));
    }
  } else {
    if (absolute_tolerances.size() != num_states) {
      return absl::InvalidArgumentError(absl::StrCat("absolute_tolerances has ",
                                                     absolute_tolerances.size(), " entries for ",
                                                     num_states, " states"));
    }
    if (!(absolute_tolerances.array() > 0.0).all() || !absolute_tolerances.allFinite()) {
      return absl::InvalidArgumentError("every absolute tolerance must be positive and finite");
    }
  }
  if (max_steps <= 0) {
    return absl::InvalidArgumentError(absl::StrCat("max_steps must be positive, got ", max_steps));
  }
  if (max_step_size < 0.0 || initial_step_size < 0.0) {
    return absl::InvalidArgumentError("max_step_size and initial_step_size must not be negative");
  }
  return absl::OkStatus();
}

CvodesIntegrator::CvodesIntegrator(int num_states, RhsFunction rhs, JacobianFunction jacobian,
                                   const CvodesOptions& options)
    : num_states_(num_states),
      rhs_(std::move(rhs)),
      jacobian_(std::move(jacobian)),
      options_(options),
      sundials_(std::make_unique<Sundials>()) {}

CvodesIntegrator::~CvodesIntegrator() = default;

namespace {

// The checks both factories make before any SUNDIALS object exists.
absl::Status ValidateCreateArguments(int num_states, const CvodesIntegrator::RhsFunction& rhs,
                                     const CvodesOptions& options, double t0,
                                     const Eigen::VectorXd& y0) {
  if (absl::Status s = options.Validate(num_states); !s.ok()) return s;
  if (!rhs) return absl::InvalidArgumentError("CvodesIntegrator needs a right-hand side");
  if (y0.size() != num_states) {
    return absl::InvalidArgumentError(
        absl::StrCat("initial state has ", y0.size(), " entries for ", num_states, " states"));
  }
  if (!y0.allFinite() || !std::isfinite(t0)) {
    return absl::InvalidArgumentError("initial time and state must be finite");
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<std::unique_ptr<CvodesIntegrator>> CvodesIntegrator::Create(
    int num_states, RhsFunction rhs, JacobianFunction jacobian, const CvodesOptions& options,
    double t0, const Eigen::VectorXd& y0) {
  if (absl::Status s = ValidateCreateArguments(num_states, rhs, options, t0, y0); !s.ok()) {
    return s;
  }
  std::unique_ptr<CvodesIntegrator> integrator(
      new CvodesIntegrator(num_states, std::move(rhs), std::move(jacobian), options));
  if (absl::Status s = integrator->Init(t0, y0); !s.ok()) return s;
  return integrator;
}

absl::StatusOr<std::unique_ptr<CvodesIntegrator>> CvodesIntegrator::CreateWithNewtonSolver(
    int num_states, RhsFunction rhs, NewtonSolveFunction newton_solve, NewtonRefresh refresh,
    const CvodesOptions& options, double t0, const Eigen::VectorXd& y0) {
  if (!newton_solve) return absl::InvalidArgumentError("CreateWithNewtonSolver needs a solver");
  if (options.iteration != CvodesOptions::Iteration::kNewton) {
    return absl::InvalidArgumentError("a Newton solver needs Newton iteration");
  }
  if (absl::Status s = ValidateCreateArguments(num_states, rhs, options, t0, y0); !s.ok()) {
    return s;
  }
  std::unique_ptr<CvodesIntegrator> integrator(
      new CvodesIntegrator(num_states, std::move(rhs), nullptr, options));
  integrator->newton_solve_ = std::move(newton_solve);
  integrator->newton_refresh_ = refresh;
  if (absl::Status s = integrator->Init(t0, y0); !s.ok()) return s;
  return integrator;
}

absl::Status CvodesIntegrator::Check(int flag, const char* call) {
  if (flag >= 0) return absl::OkStatus();
  std::string message = absl::StrFormat("%s failed (%d)", call, flag);
  if (!last_sundials_message_.empty()) absl::StrAppend(&message, ": ", last_sundials_message_);
  return absl::InternalError(message);
}

absl::Status CvodesIntegrator::Init(double t0, const Eigen::VectorXd& y0) {
  Sundials& s = *sundials_;
  s.context = MakeContext();
  if (!s.context) {
    return absl::InternalError("SUNContext_Create failed");
  }
  s.y.reset(N_VNew_Serial(num_states_, s.context.get()));
  if (!s.y) return absl::InternalError("N_VNew_Serial failed");
  std::copy(y0.data(), y0.data() + num_states_, N_VGetArrayPointer(s.y.get()));
  // Fused vector operations: fewer passes over the (small) state vectors per
  // step; CVODES' internal vectors are cloned from this one and inherit it.
  if (N_VEnableFusedOps_Serial(s.y.get(), SUNTRUE) != 0) {
    return absl::InternalError("N_VEnableFusedOps_Serial failed");
  }
  s.cvode.reset(CVodeCreate(options_.method == CvodesOptions::Method::kBdf ? CV_BDF : CV_ADAMS, s.context.get()));
  if (!s.cvode) return absl::InternalError("CVodeCreate failed");
  MBOPT_RETURN_IF_ERROR(
      Check(CVodeSetErrHandlerFn(s.cvode.get(), &CaptureMessage, &last_sundials_message_),
            "CVodeSetErrHandlerFn"));
  MBOPT_RETURN_IF_ERROR(Check(CVodeInit(s.cvode.get(), &CvodesCallbacks::Rhs, t0, s.y.get()), "CVodeInit"));
  MBOPT_RETURN_IF_ERROR(Check(CVodeSetUserData(s.cvode.get(), this), "CVodeSetUserData"));
  if (options_.absolute_tolerances.size() == 0) {
    MBOPT_RETURN_IF_ERROR(
        Check(CVodeSStolerances(s.cvode.get(), options_.relative_tolerance, options_.absolute_tolerance),
              "CVodeSStolerances"));
  } else {
    s.abstol.reset(N_VNew_Serial(num_states_, s.context.get()));
    if (!s.abstol) return absl::InternalError("N_VNew_Serial failed");
    std::copy(options_.absolute_tolerances.data(),
              options_.absolute_tolerances.data() + num_states_, N_VGetArrayPointer(s.abstol.get()));
    MBOPT_RETURN_IF_ERROR(Check(CVodeSVtolerances(s.cvode.get(), options_.relative_tolerance, s.abstol.get()),
                                "CVodeSVtolerances"));
  }
  if (options_.iteration == CvodesOptions::Iteration::kFixedPoint) {
    s.nonlinear_solver.reset(SUNNonlinSol_FixedPoint(s.y.get(), 0, s.context.get()));
    if (!s.nonlinear_solver) return absl::InternalError("SUNNonlinSol_FixedPoint failed");
    MBOPT_RETURN_IF_ERROR(
        Check(CVodeSetNonlinearSolver(s.cvode.get(), s.nonlinear_solver.get()), "CVodeSetNonlinearSolver"));
  } else {
    MBOPT_RETURN_IF_ERROR(InitLinearSolver());
  }
  if (options_.max_step_size > 0.0) {
    MBOPT_RETURN_IF_ERROR(
        Check(CVodeSetMaxStep(s.cvode.get(), options_.max_step_size), "CVodeSetMaxStep"));
  }
  if (options_.initial_step_size > 0.0) {
    MBOPT_RETURN_IF_ERROR(
        Check(CVodeSetInitStep(s.cvode.get(), options_.initial_step_size), "CVodeSetInitStep"));
  }
  t_ = t0;
  return absl::OkStatus();
}

absl::Status CvodesIntegrator::InitLinearSolver() {
  Sundials& s = *sundials_;
  if (newton_solve_) {
    s.linear_solver.reset(SUNLinSolNewEmpty(s.context.get()));
    if (!s.linear_solver) return absl::InternalError("SUNLinSolNewEmpty failed");
    s.linear_solver.get()->content = this;
    s.linear_solver.get()->ops->gettype = &CvodesCallbacks::NewtonType;
    s.linear_solver.get()->ops->getid = &CvodesCallbacks::NewtonId;
    s.linear_solver.get()->ops->solve = &CvodesCallbacks::NewtonSolve;
    s.linear_solver.get()->ops->free = &CvodesCallbacks::NewtonFree;
    if (newton_refresh_ == NewtonRefresh::kEveryIteration) {
      return Check(CVodeSetLinearSolver(s.cvode.get(), s.linear_solver.get(), nullptr),
                   "CVodeSetLinearSolver");
    }
    // CVODES' direct-solver interface wants a matrix; the caller owns the
    // real one, so a 1 x 1 placeholder stands in and is never read.
    s.matrix.reset(SUNDenseMatrix(1, 1, s.context.get()));
    if (!s.matrix) return absl::InternalError("SUNDenseMatrix failed");
    MBOPT_RETURN_IF_ERROR(
        Check(CVodeSetLinearSolver(s.cvode.get(), s.linear_solver.get(), s.matrix.get()), "CVodeSetLinearSolver"));
    return Check(CVodeSetLinSysFn(s.cvode.get(), &CvodesCallbacks::LinSys), "CVodeSetLinSysFn");
  }
  s.matrix.reset(SUNDenseMatrix(num_states_, num_states_, s.context.get()));
  if (!s.matrix) return absl::InternalError("SUNDenseMatrix failed");
  s.linear_solver.reset(SUNLinSol_Dense(s.y.get(), s.matrix.get(), s.context.get()));
  if (!s.linear_solver) return absl::InternalError("SUNLinSol_Dense failed");
  MBOPT_RETURN_IF_ERROR(
      Check(CVodeSetLinearSolver(s.cvode.get(), s.linear_solver.get(), s.matrix.get()), "CVodeSetLinearSolver"));
  if (jacobian_) {
    MBOPT_RETURN_IF_ERROR(
        Check(CVodeSetJacFn(s.cvode.get(), &CvodesCallbacks::Jacobian), "CVodeSetJacFn"));
  }
  return absl::OkStatus();
}

absl::Status CvodesIntegrator::SetStopTime(double t_stop) {
  if (!(t_stop > t_)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("stop time %.9g is not ahead of the current time %.9g", t_stop, t_));
  }
  MBOPT_RETURN_IF_ERROR(Check(CVodeSetStopTime(sundials_->cvode.get(), t_stop), "CVodeSetStopTime"));
  stop_time_ = t_stop;
  stop_time_set_ = true;
  return absl::OkStatus();
}

absl::Status CvodesIntegrator::Restart(double t, const Eigen::VectorXd& y) {
  if (y.size() != num_states_ || !y.allFinite()) {
    return absl::InvalidArgumentError("restart state has the wrong size or is not finite");
  }
  AccumulateCounters();
  std::copy(y.data(), y.data() + num_states_, N_VGetArrayPointer(sundials_->y.get()));
  MBOPT_RETURN_IF_ERROR(Check(CVodeReInit(sundials_->cvode.get(), t, sundials_->y.get()), "CVodeReInit"));
  if (stop_time_set_ && stop_time_ <= t) {
    // CVODES 6.4 keeps a stop time across CVodeReInit and has no call to
    // clear it; one at or behind the restart time would fail the next step,
    // so it is moved out of reach.
    MBOPT_RETURN_IF_ERROR(
        Check(CVodeSetStopTime(sundials_->cvode.get(), std::numeric_limits<double>::max()),
              "CVodeSetStopTime"));
    stop_time_set_ = false;
  }
  ++carried_.restarts;
  t_ = t;
  return absl::OkStatus();
}

void CvodesIntegrator::AccumulateCounters() {
  const CvodesCounters now = counters();
  const std::int64_t restarts = carried_.restarts;
  carried_ = now;
  carried_.restarts = restarts;
  // counters() adds the life-long refactorization count itself.
  carried_.jacobian_evaluations -= newton_refactorizations_;
}

CvodesCounters CvodesIntegrator::counters() const {
  CvodesCounters c = carried_;
  c.jacobian_evaluations += newton_refactorizations_;
  void* mem = sundials_->cvode.get();
  if (mem == nullptr) return c;
  long value = 0;
  if (CVodeGetNumSteps(mem, &value) == CV_SUCCESS) c.steps += value;
  if (CVodeGetNumRhsEvals(mem, &value) == CV_SUCCESS) c.rhs_evaluations += value;
  if (CVodeGetNumLinRhsEvals(mem, &value) == CV_SUCCESS) c.rhs_evaluations += value;
  // With the caller's Newton solver CVODES' count is of its setups, not of
  // factorizations; those are counted above.
  if (!newton_solve_ && CVodeGetNumJacEvals(mem, &value) == CV_SUCCESS) {
    c.jacobian_evaluations += value;
  }
  if (CVodeGetNumNonlinSolvIters(mem, &value) == CV_SUCCESS) c.nonlinear_iterations += value;
  if (CVodeGetNumNonlinSolvConvFails(mem, &value) == CV_SUCCESS) {
    c.nonlinear_convergence_failures += value;
  }
  if (CVodeGetNumErrTestFails(mem, &value) == CV_SUCCESS) c.error_test_failures += value;
  return c;
}

absl::Status CvodesIntegrator::IntegrateTo(double t_out, Eigen::VectorXd* y) {
  if (y == nullptr) return absl::InvalidArgumentError("IntegrateTo needs an output vector");
  if (!(t_out >= t_)) {
    return absl::InvalidArgumentError(
        absl::StrFormat("output time %.9g is behind the current time %.9g", t_out, t_));
  }
  Sundials& s = *sundials_;
  y->resize(num_states_);
  constexpr double kNegligibleInterval = 1e-13;
  if (t_out - t_ <= kNegligibleInterval * std::max(1.0, std::abs(t_))) {
    // CVODES refuses a zero or rounding-size request ("tout too close to
    // t0"), e.g. a grid instant one ulp after a restart; the state there is
    // the current one to within rounding.
    const double* data = N_VGetArrayPointer(s.y.get());
    std::copy(data, data + num_states_, y->data());
    t_ = t_out;
    return absl::OkStatus();
  }
  // CVODES may already have stepped to (or past) t_out while producing the
  // previous output; then the answer is an interpolation within its last
  // step. Asking CVode instead would fail when that step ended exactly on a
  // stop time ("tstop is behind current t").
  double t_internal = t_;
  MBOPT_RETURN_IF_ERROR(Check(CVodeGetCurrentTime(s.cvode.get(), &t_internal), "CVodeGetCurrentTime"));
  if (t_out <= t_internal) {
    MBOPT_RETURN_IF_ERROR(Check(CVodeGetDky(s.cvode.get(), t_out, 0, s.y.get()), "CVodeGetDky"));
    const double* data = N_VGetArrayPointer(s.y.get());
    std::copy(data, data + num_states_, y->data());
    t_ = t_out;
    if (!y->allFinite()) {
      return absl::AbortedError(absl::StrFormat("state is not finite at t = %.9g", t_));
    }
    return absl::OkStatus();
  }
  if (options_.budget != nullptr) {
    if (spec::AnalysisFailure f = options_.budget->Check(t_); !f.ok()) return BudgetStatus(f);
  }
  const std::int64_t used = counters().steps;
  const std::int64_t remaining = options_.max_steps - used;
  if (remaining <= 0) {
    return absl::AbortedError(
        absl::StrFormat("step budget of %d exhausted at t = %.9g", options_.max_steps, t_));
  }
  MBOPT_RETURN_IF_ERROR(
      Check(CVodeSetMaxNumSteps(s.cvode.get(), static_cast<long>(remaining)), "CVodeSetMaxNumSteps"));
  last_sundials_message_.clear();
  callback_failure_.clear();
  budget_failure_ = spec::AnalysisFailure::Ok();
  double t_reached = t_;
  const int flag = CVode(s.cvode.get(), t_out, s.y.get(), &t_reached, CV_NORMAL);
  if (flag < 0) {
    if (!budget_failure_.ok()) {
      t_ = t_reached;
      return BudgetStatus(budget_failure_);
    }
    std::string reason;
    switch (flag) {
      case CV_TOO_MUCH_WORK:
        reason = absl::StrFormat("step budget of %d exhausted", options_.max_steps);
        break;
      case CV_TOO_MUCH_ACC:
        reason = "the requested accuracy cannot be reached";
        break;
      case CV_ERR_FAILURE:
        reason = "repeated error test failures";
        break;
      case CV_CONV_FAILURE:
        reason = "repeated nonlinear convergence failures";
        break;
      case CV_RHSFUNC_FAIL:
      case CV_FIRST_RHSFUNC_ERR:
      case CV_REPTD_RHSFUNC_ERR:
      case CV_UNREC_RHSFUNC_ERR:
        reason = "the right-hand side failed";
        break;
      default:
        reason = absl::StrFormat("CVode returned %d", flag);
    }
    std::string message = absl::StrFormat("integrator failed near t = %.9g (target %.9g): %s",
                                          t_reached, t_out, reason);
    if (!callback_failure_.empty()) absl::StrAppend(&message, ": ", callback_failure_);
    if (!last_sundials_message_.empty())
      absl::StrAppend(&message, " [", last_sundials_message_, "]");
    t_ = t_reached;
    return absl::AbortedError(message);
  }
  t_ = t_reached;
  const double* data = N_VGetArrayPointer(s.y.get());
  std::copy(data, data + num_states_, y->data());
  if (!y->allFinite()) {
    return absl::AbortedError(absl::StrFormat("state is not finite at t = %.9g", t_));
  }
  return absl::OkStatus();
}

}  // namespace mbopt::sundials
