#include "worker/multibody/forward_dynamics.h"

#include <idas/idas.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <chrono>
#include <cmath>
#include <exception>
#include <string>

#include "absl/strings/str_format.h"
#include "worker/solve/sundials_handles.h"

namespace mbopt::multibody {
namespace {

using Eigen::Map;
using Eigen::VectorXd;

// What the residual callback needs; lives for one integration.
struct Problem {
  const ConstrainedSystem* system = nullptr;
  int n = 0, m = 0;
  std::chrono::steady_clock::time_point start;
  double max_wall_seconds = 0.0;
  bool wall_time_exceeded = false;
  std::string callback_failure;
  // Work space.
  Eigen::MatrixXd mass, phi_q;
  VectorXd forces, phi, phi_t;
};

int Residual(realtype t, N_Vector yy, N_Vector yp, N_Vector rr, void* user_data) {
  auto* p = static_cast<Problem*>(user_data);
  try {
    if (p->max_wall_seconds > 0.0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - p->start).count() > p->max_wall_seconds) {
      p->wall_time_exceeded = true;
      return -1;
    }
    const int n = p->n, m = p->m;
    const Map<const VectorXd> y(N_VGetArrayPointer(yy), 2 * n + 2 * m);
    const Map<const VectorXd> y_dot(N_VGetArrayPointer(yp), 2 * n + 2 * m);
    Map<VectorXd> r(N_VGetArrayPointer(rr), 2 * n + 2 * m);
    const VectorXd q = y.head(n), v = y.segment(n, n);
    const ConstrainedSystem& s = *p->system;
    int flag = s.MassMatrix(q, &p->mass);
    if (flag == 0) flag = s.AppliedForces(t, q, v, &p->forces);
    if (flag == 0 && m > 0) flag = s.ConstraintJacobian(t, q, &p->phi_q);
    if (flag == 0 && m > 0) flag = s.Constraints(t, q, &p->phi);
    if (flag == 0 && m > 0) flag = s.ConstraintTimeDerivative(t, q, &p->phi_t);
    if (flag != 0) return flag;
    r.head(n) = y_dot.head(n) - v;
    r.segment(n, n) = p->mass * y_dot.segment(n, n) - p->forces;
    if (m > 0) {
      r.head(n) += p->phi_q.transpose() * y.segment(2 * n + m, m);
      r.segment(n, n) += p->phi_q.transpose() * y.segment(2 * n, m);
      r.segment(2 * n, m) = p->phi;
      r.segment(2 * n + m, m) = p->phi_q * v + p->phi_t;
    }
    return r.allFinite() ? 0 : 1;
  } catch (const std::exception& e) {
    p->callback_failure = e.what();
    return -1;
  } catch (...) {
    p->callback_failure = "unknown exception in the residual";
    return -1;
  }
}

void Accumulate(void* ida, ForwardDynamicsCounters* c) {
  long value = 0;
  if (IDAGetNumSteps(ida, &value) == IDA_SUCCESS) c->steps = value;
  if (IDAGetNumResEvals(ida, &value) == IDA_SUCCESS) c->residual_evaluations = value;
  if (IDAGetNumJacEvals(ida, &value) == IDA_SUCCESS) c->jacobian_evaluations = value;
  if (IDAGetNumNonlinSolvIters(ida, &value) == IDA_SUCCESS) c->nonlinear_iterations = value;
  if (IDAGetNumErrTestFails(ida, &value) == IDA_SUCCESS) c->error_test_failures = value;
  if (IDAGetNumNonlinSolvConvFails(ida, &value) == IDA_SUCCESS) c->convergence_failures = value;
}

// Newton's convergence weight of the stabilizing multipliers mu (see
// IntegrateForward).
constexpr double kMuTolerance = 1e-3;

spec::AnalysisFailure Failed(spec::FailureKind kind, std::string reason) {
  return spec::AnalysisFailure::Of(kind, std::move(reason));
}

}  // namespace

spec::AnalysisFailure IntegrateForward(const ConstrainedSystem& system, double t0, const VectorXd& q0,
                                       const VectorXd& v0, const std::vector<double>& times,
                                       const ForwardDynamicsOptions& options, const MotionCallback& at_instant,
                                       ForwardDynamicsCounters* counters) {
  Problem p;
  p.system = &system;
  p.n = system.num_coordinates();
  p.m = system.num_constraints();
  p.start = std::chrono::steady_clock::now();
  p.max_wall_seconds = options.max_wall_seconds;
  const int n = p.n, m = p.m, size = 2 * n + 2 * m;
  if (q0.size() != n || v0.size() != n) {
    return Failed(spec::FailureKind::kInvalidModel, "initial coordinates of the wrong size");
  }

  // Consistent accelerations and multipliers at t0.
  Eigen::MatrixXd mass, phi_q;
  VectorXd forces, gamma;
  if (system.MassMatrix(q0, &mass) != 0 || system.AppliedForces(t0, q0, v0, &forces) != 0 ||
      (m > 0 && (system.ConstraintJacobian(t0, q0, &phi_q) != 0 ||
                 system.AccelerationRightSide(t0, q0, v0, &gamma) != 0))) {
    if (!system.FailureReason().empty()) return Failed(spec::FailureKind::kModelValidity, system.FailureReason());
    return Failed(spec::FailureKind::kNonFiniteValue, absl::StrFormat("the equations are not finite at t = %.6g s", t0));
  }
  Eigen::MatrixXd augmented = Eigen::MatrixXd::Zero(n + m, n + m);
  augmented.topLeftCorner(n, n) = mass;
  VectorXd rhs(n + m);
  rhs.head(n) = forces;
  if (m > 0) {
    augmented.topRightCorner(n, m) = phi_q.transpose();
    augmented.bottomLeftCorner(m, n) = phi_q;
    rhs.tail(m) = gamma;
  }
  Eigen::FullPivLU<Eigen::MatrixXd> lu(augmented);
  // Singular: redundant constraints or a locked position; the multipliers
  // would not be unique and IDAS's Newton matrix would be singular too.
  if (!lu.isInvertible()) {
    return Failed(spec::FailureKind::kAssembly,
                  absl::StrFormat("singular equations of motion at t = %.6g s: redundant joints or a locked position "
                                  "(rank %d of %d)",
                                  t0, static_cast<int>(lu.rank()), n + m));
  }
  const VectorXd accelerations_multipliers = lu.solve(rhs);

  namespace sd = solve::sundials;
  struct Handles {
    sd::Context context;
    sd::Vector yy, yp, id, atol;
    sd::Matrix matrix;
    sd::LinearSolver linear_solver;
    sd::Memory<&IDAFree> ida;
  } h;
  std::string sundials_message;
  h.context = sd::MakeContext();
  if (!h.context) return Failed(spec::FailureKind::kIntegrator, "SUNContext_Create failed");
  h.yy.reset(N_VNew_Serial(size, h.context.get()));
  h.yp.reset(N_VNew_Serial(size, h.context.get()));
  h.id.reset(N_VNew_Serial(size, h.context.get()));
  if (!h.yy || !h.yp || !h.id) return Failed(spec::FailureKind::kIntegrator, "SUNDIALS allocation failed");
  Map<VectorXd> y(N_VGetArrayPointer(h.yy.get()), size), y_dot(N_VGetArrayPointer(h.yp.get()), size),
      id(N_VGetArrayPointer(h.id.get()), size);
  y.setZero();
  y_dot.setZero();
  y.head(n) = q0;
  y.segment(n, n) = v0;
  y_dot.head(n) = v0;
  y_dot.segment(n, n) = accelerations_multipliers.head(n);
  if (m > 0) y.segment(2 * n, m) = accelerations_multipliers.tail(m);
  id.head(2 * n).setOnes();
  id.tail(2 * m).setZero();
  // The multipliers are left out of the error test; their weights only enter
  // Newton's convergence test. lambda gets the coordinates' tolerance. mu is
  // zero on the exact solution and only absorbs the drift, so its Newton
  // corrections are round-off: weighting them like the coordinates makes the
  // corrector fail within the first steps (seen with 1e-9 and 1e-6 on the
  // double pendulum and SUNDIALS' slider-crank; none with 1e-3, and the
  // answers do not change beyond the integration tolerance between 1e-3
  // and 1e-1).
  h.atol.reset(N_VNew_Serial(size, h.context.get()));
  if (!h.atol) return Failed(spec::FailureKind::kIntegrator, "SUNDIALS allocation failed");
  Map<VectorXd> atol(N_VGetArrayPointer(h.atol.get()), size);
  atol.head(2 * n).setConstant(options.absolute_tolerance);
  atol.segment(2 * n, m).setConstant(options.absolute_tolerance);
  atol.tail(m).setConstant(kMuTolerance);
  h.matrix.reset(SUNDenseMatrix(size, size, h.context.get()));
  if (!h.matrix) return Failed(spec::FailureKind::kIntegrator, "SUNDenseMatrix failed");
  h.linear_solver.reset(SUNLinSol_Dense(h.yy.get(), h.matrix.get(), h.context.get()));
  h.ida.reset(IDACreate(h.context.get()));
  if (!h.linear_solver || !h.ida) return Failed(spec::FailureKind::kIntegrator, "SUNDIALS allocation failed");
  void* ida = h.ida.get();
  auto check = [&](int flag, const char* call) {
    if (flag >= 0) return true;
    sundials_message = absl::StrFormat("%s failed (%d)%s%s", call, flag, sundials_message.empty() ? "" : ": ",
                                       sundials_message);
    return false;
  };
  bool ok = check(IDASetErrHandlerFn(ida, &sd::CaptureMessage, &sundials_message), "IDASetErrHandlerFn") &&
            check(IDAInit(ida, &Residual, t0, h.yy.get(), h.yp.get()), "IDAInit") &&
            check(IDASetUserData(ida, &p), "IDASetUserData") &&
            check(IDASVtolerances(ida, options.relative_tolerance, h.atol.get()), "IDASVtolerances") &&
            check(IDASetLinearSolver(ida, h.linear_solver.get(), h.matrix.get()), "IDASetLinearSolver") &&
            check(IDASetId(ida, h.id.get()), "IDASetId") &&
            check(IDASetSuppressAlg(ida, SUNTRUE), "IDASetSuppressAlg") &&
            check(IDASetMaxNumSteps(ida, options.max_steps), "IDASetMaxNumSteps") &&
            (options.max_step_size <= 0.0 || check(IDASetMaxStep(ida, options.max_step_size), "IDASetMaxStep"));
  if (!ok) return Failed(spec::FailureKind::kIntegrator, sundials_message);

  VectorXd phi, phi_t;
  double t_reached = t0;
  for (double t : times) {
    if (t > t_reached) {
      const int flag = IDASolve(ida, t, &t_reached, h.yy.get(), h.yp.get(), IDA_NORMAL);
      Accumulate(ida, counters);
      if (flag < 0) {
        if (!system.FailureReason().empty()) {
          return Failed(spec::FailureKind::kModelValidity,
                        absl::StrFormat("%s; the integrator gave up near t = %.6g s", system.FailureReason(), t_reached));
        }
        if (p.wall_time_exceeded) {
          return Failed(spec::FailureKind::kTimeLimit,
                        absl::StrFormat("the wall-time limit of %g s was reached near t = %.6g s", p.max_wall_seconds,
                                        t_reached));
        }
        return Failed(spec::FailureKind::kIntegrator,
                      absl::StrFormat("the integrator failed near t = %.6g s (target %.6g s): %s%s", t_reached, t,
                                      sundials_message, p.callback_failure.empty() ? "" : " [" + p.callback_failure + "]"));
      }
    }
    MotionSample sample;
    sample.t_s = t;
    sample.q = y.head(n);
    sample.v = y.segment(n, n);
    sample.a = y_dot.segment(n, n);
    sample.lambda = y.segment(2 * n, m);
    if (m > 0) {
      system.Constraints(t, sample.q, &phi);
      system.ConstraintJacobian(t, sample.q, &phi_q);
      system.ConstraintTimeDerivative(t, sample.q, &phi_t);
      counters->max_position_drift = std::max(counters->max_position_drift, MaxAbs(phi));
      counters->max_velocity_drift =
          std::max(counters->max_velocity_drift, MaxAbs(phi_q * sample.v + phi_t));
    }
    if (spec::AnalysisFailure f = at_instant(sample); !f.ok()) return f;
  }
  Accumulate(ida, counters);
  return spec::AnalysisFailure::Ok();
}

}  // namespace mbopt::multibody
