// CVODES' forward sensitivity module (CVodeSensInit) on the lumped model:
// kept as an option beside the augmented system, which is faster for small
// models (docs/method.md section 4 has the measurements).
#include <cvodes/cvodes.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "worker/sundials/integrator_failure.h"
#include "worker/lumped/lumped_sensitivity_problem.h"
#include "worker/sundials/sundials_handles.h"

namespace mbopt::lumped::sensitivity_internal {
namespace {

int Rhs(realtype t, N_Vector y, N_Vector ydot, void* user_data) {
  auto* p = static_cast<SensitivityProblem*>(user_data);
  if (p->budget != nullptr && p->budget->Exhausted()) {
    p->budget_failure = p->budget->Check(t);
    if (!p->budget_failure.ok()) return -1;
  }
  const int n = p->n;
  Eigen::Map<const Eigen::VectorXd> q(N_VGetArrayPointer(y), n), v(N_VGetArrayPointer(y) + n, n);
  Eigen::Map<Eigen::VectorXd> qdot(N_VGetArrayPointer(ydot), n),
      vdot(N_VGetArrayPointer(ydot) + n, n);
  qdot = v;
  p->model->Forcing(t, &p->force);
  vdot = p->inverse_mass.cwiseProduct(p->force);
  vdot.noalias() -= p->minv_k * q;
  vdot.noalias() -= p->minv_c * v;
  return vdot.allFinite() ? 0 : -1;
}

int SensitivityRhs(int num_sensitivities, realtype t, N_Vector y, N_Vector ydot, N_Vector* ys,
                   N_Vector* ysdot, void* user_data, N_Vector, N_Vector) {
  auto* p = static_cast<SensitivityProblem*>(user_data);
  const int n = p->n;
  const Eigen::Map<const Eigen::VectorXd> q(N_VGetArrayPointer(y), n),
      v(N_VGetArrayPointer(y) + n, n), qddot(N_VGetArrayPointer(ydot) + n, n);
  for (int k = 0; k < num_sensitivities; ++k) {
    const double* in = N_VGetArrayPointer(ys[k]);
    double* out = N_VGetArrayPointer(ysdot[k]);
    const Eigen::Map<const Eigen::VectorXd> s(in, n), sv(in + n, n);
    Eigen::Map<Eigen::VectorXd> a(out + n, n);
    p->AccelerationDerivative(k, t, q, v, qddot, s, sv, a);
    Eigen::Map<Eigen::VectorXd>(out, n) = sv;
    if (!a.allFinite()) return -1;
  }
  return 0;
}

// CV_STAGGERED1's form: one sensitivity per call.
int SensitivityRhs1(int, realtype t, N_Vector y, N_Vector ydot, int k, N_Vector ys,
                    N_Vector ysdot, void* user_data, N_Vector, N_Vector) {
  auto* p = static_cast<SensitivityProblem*>(user_data);
  const int n = p->n;
  const Eigen::Map<const Eigen::VectorXd> q(N_VGetArrayPointer(y), n),
      v(N_VGetArrayPointer(y) + n, n), qddot(N_VGetArrayPointer(ydot) + n, n);
  const double* in = N_VGetArrayPointer(ys);
  double* out = N_VGetArrayPointer(ysdot);
  const Eigen::Map<const Eigen::VectorXd> s(in, n), sv(in + n, n);
  Eigen::Map<Eigen::VectorXd> a(out + n, n);
  p->AccelerationDerivative(k, t, q, v, qddot, s, sv, a);
  Eigen::Map<Eigen::VectorXd>(out, n) = sv;
  return a.allFinite() ? 0 : -1;
}

int Jacobian(realtype, N_Vector, N_Vector, SUNMatrix jac, void* user_data, N_Vector, N_Vector,
             N_Vector) {
  auto* p = static_cast<SensitivityProblem*>(user_data);
  const int n = p->n;
  Eigen::Map<Eigen::MatrixXd> j(SUNDenseMatrix_Data(jac), 2 * n, 2 * n);
  j.setZero();
  j.topRightCorner(n, n).setIdentity();
  j.bottomLeftCorner(n, n) = -p->minv_k;
  j.bottomRightCorner(n, n) = -p->minv_c;
  return 0;
}

// Owns every SUNDIALS object of one integration, in the order of creation
// (sundials_handles.h).
struct Sundials {
  sundials::Context context;
  sundials::Vector y;
  sundials::Vector abstol;
  sundials::Matrix matrix;
  sundials::LinearSolver linear_solver;
  sundials::VectorArray ys;
  sundials::Memory<&CVodeFree> cvode;
};

}  // namespace

spec::AnalysisFailure IntegrateWithSensitivityModule(SensitivityProblem* p,
                                           const spec::IntegratorSettings& settings,
                                           const LumpedSensitivityOptions& options, double omega_max,
                                           const std::vector<double>& pbar,
                                           const std::vector<double>& instants,
                                           const SensitivityRecorder& record,
                                           spec::AnalysisCounters* counters,
                                           LumpedSensitivityCounters* sensitivity_counters) {
  const LumpedModel& m = *p->model;
  const int n = p->n;
  const int ns = static_cast<int>(p->derivatives.size());
  // CVODES takes the scales as a non-const pointer.
  std::vector<double> parameter_scales = pbar;
  Sundials s;
  std::string failure;
  auto check = [&](int flag, const char* call) {
    if (flag >= 0 || !failure.empty()) return flag >= 0;
    failure = absl::StrFormat("%s failed (%d)", call, flag);
    if (!p->sundials_message.empty()) absl::StrAppend(&failure, ": ", p->sundials_message);
    return false;
  };
  if (!(options.tolerance_factor > 0.0) || !std::isfinite(options.tolerance_factor)) {
    return spec::AnalysisFailure::Of(spec::FailureKind::kInvalidModel,
                                     absl::StrCat("sensitivity tolerance factor must be positive, got ",
                                                  options.tolerance_factor));
  }
  s.context = sundials::MakeContext();
  if (!s.context) {
    return spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, "SUNContext_Create failed");
  }
  s.y.reset(N_VNew_Serial(2 * n, s.context.get()));
  s.abstol.reset(N_VNew_Serial(2 * n, s.context.get()));
  s.cvode.reset(CVodeCreate(CV_BDF, s.context.get()));
  if (!s.y || !s.abstol || !s.cvode) {
    return spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, "SUNDIALS allocation failed");
  }
  if (options.fused_vector_operations && N_VEnableFusedOps_Serial(s.y.get(), SUNTRUE) != 0) {
    return spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, "N_VEnableFusedOps_Serial failed");
  }
  Eigen::Map<Eigen::VectorXd> y(N_VGetArrayPointer(s.y.get()), 2 * n);
  y.setZero();
  Eigen::Map<Eigen::VectorXd> abstol(N_VGetArrayPointer(s.abstol.get()), 2 * n);
  abstol.head(n).setConstant(settings.absolute_tolerance);
  abstol.tail(n).setConstant(settings.absolute_tolerance * std::max(1.0, omega_max));
  s.matrix.reset(SUNDenseMatrix(2 * n, 2 * n, s.context.get()));
  s.linear_solver.reset(SUNLinSol_Dense(s.y.get(), s.matrix.get(), s.context.get()));
  s.ys = sundials::VectorArray(N_VCloneVectorArray(ns, s.y.get()), ns);
  if (!s.matrix || !s.linear_solver || !s.ys) {
    return spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, "SUNDIALS allocation failed");
  }
  for (int k = 0; k < ns; ++k) N_VConst(0.0, s.ys[k]);
  int corrector = CV_STAGGERED;
  switch (options.corrector) {
    case LumpedSensitivityOptions::Corrector::kSimultaneous: corrector = CV_SIMULTANEOUS; break;
    case LumpedSensitivityOptions::Corrector::kStaggered: corrector = CV_STAGGERED; break;
    case LumpedSensitivityOptions::Corrector::kStaggered1: corrector = CV_STAGGERED1; break;
  }
  // Sensitivity tolerances: EE's own choice (rtol, atol_i / pbar_k), or the
  // same scaled by options.tolerance_factor.
  const bool estimated_tolerances = options.tolerance_factor == 1.0;
  sundials::VectorArray sensitivity_abstol;
  if (!estimated_tolerances) {
    sensitivity_abstol = sundials::VectorArray(N_VCloneVectorArray(ns, s.y.get()), ns);
    if (!sensitivity_abstol) {
      return spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, "SUNDIALS allocation failed");
    }
    for (int k = 0; k < ns; ++k) {
      N_VScale(options.tolerance_factor / pbar[static_cast<size_t>(k)], s.abstol.get(), sensitivity_abstol[k]);
    }
  }
  bool ok = check(CVodeSetErrHandlerFn(s.cvode.get(), &sundials::CaptureMessage, &p->sundials_message),
                  "CVodeSetErrHandlerFn") &&
            check(CVodeInit(s.cvode.get(), &Rhs, 0.0, s.y.get()), "CVodeInit") &&
            check(CVodeSetUserData(s.cvode.get(), p), "CVodeSetUserData") &&
            check(CVodeSVtolerances(s.cvode.get(), settings.relative_tolerance, s.abstol.get()),
                  "CVodeSVtolerances") &&
            check(CVodeSetLinearSolver(s.cvode.get(), s.linear_solver.get(), s.matrix.get()),
                  "CVodeSetLinearSolver") &&
            check(CVodeSetJacFn(s.cvode.get(), &Jacobian), "CVodeSetJacFn") &&
            check(CVodeSetMaxNumSteps(s.cvode.get(), settings.max_steps), "CVodeSetMaxNumSteps") &&
            (options.jacobian_eval_frequency <= 0 ||
             check(CVodeSetJacEvalFrequency(s.cvode.get(), options.jacobian_eval_frequency),
                   "CVodeSetJacEvalFrequency")) &&
            (options.linear_setup_frequency <= 0 ||
             check(CVodeSetLSetupFrequency(s.cvode.get(), options.linear_setup_frequency),
                   "CVodeSetLSetupFrequency")) &&
            (corrector == CV_STAGGERED1
                 ? check(CVodeSensInit1(s.cvode.get(), ns, corrector, &SensitivityRhs1, s.ys.get()),
                         "CVodeSensInit1")
                 : check(CVodeSensInit(s.cvode.get(), ns, corrector, &SensitivityRhs, s.ys.get()),
                         "CVodeSensInit")) &&
            check(CVodeSetSensParams(s.cvode.get(), nullptr, parameter_scales.data(), nullptr),
                  "CVodeSetSensParams") &&
            (estimated_tolerances
                 ? check(CVodeSensEEtolerances(s.cvode.get()), "CVodeSensEEtolerances")
                 : check(CVodeSensSVtolerances(
                             s.cvode.get(), settings.relative_tolerance * options.tolerance_factor,
                             sensitivity_abstol.get()),
                         "CVodeSensSVtolerances")) &&
            check(CVodeSetSensErrCon(s.cvode.get(), options.error_control ? SUNTRUE : SUNFALSE),
                  "CVodeSetSensErrCon");

  const double t_last = instants.empty() ? 0.0 : instants.back();
  const std::vector<double> kinks = m.KinkTimes(0.0, t_last);
  size_t next_kink = 0;
  double t_now = 0.0;
  auto set_stop = [&]() {
    const double stop = next_kink < kinks.size() ? kinks[next_kink] : t_last;
    return stop <= t_now || check(CVodeSetStopTime(s.cvode.get(), stop), "CVodeSetStopTime");
  };
  auto advance = [&](double t) {
    if (t <= t_now) return true;
    realtype reached = t_now;
    const int flag = CVode(s.cvode.get(), t, s.y.get(), &reached, CV_NORMAL);
    if (flag < 0) {
      failure = absl::StrFormat("integrator failed near t = %.9g (target %.9g): flag %d", reached,
                                t, flag);
      if (!p->sundials_message.empty()) absl::StrAppend(&failure, " [", p->sundials_message, "]");
      return false;
    }
    t_now = t;
    realtype t_sens = t;
    return check(CVodeGetSens(s.cvode.get(), &t_sens, s.ys.get()), "CVodeGetSens");
  };
  ok = ok && set_stop();
  // CVodeReInit (at every kink) zeroes CVODES' counters: they are summed
  // over the histories.
  bool history_counted = false;  // until the next CVodeReInit
  auto accumulate_counters = [&]() {
    long value = 0;
    auto add = [&](int (*get)(void*, long*), auto* total) {
      value = 0;
      if (get(s.cvode.get(), &value) == CV_SUCCESS) *total += value;
    };
    add(&CVodeGetNumSteps, &counters->time_steps);
    add(&CVodeGetNumRhsEvals, &counters->rhs_evaluations);
    add(&CVodeGetNumJacEvals, &counters->jacobian_evaluations);
    add(&CVodeGetNumNonlinSolvIters, &counters->newton_iterations);
    LumpedSensitivityCounters& c = *sensitivity_counters;
    add(&CVodeGetSensNumRhsEvals, &c.sensitivity_rhs_evaluations);
    add(&CVodeGetSensNumNonlinSolvIters, &c.sensitivity_newton_iterations);
    add(&CVodeGetNumLinSolvSetups, &c.linear_setups);
    add(&CVodeGetNumErrTestFails, &c.error_test_failures);
    add(&CVodeGetSensNumErrTestFails, &c.sensitivity_error_test_failures);
  };
  for (size_t i = 0; ok && i < instants.size(); ++i) {
    const double t = instants[i];
    while (ok && next_kink < kinks.size() && kinks[next_kink] <= t) {
      const double kink = kinks[next_kink++];
      if (!advance(kink)) {
        ok = false;
        break;
      }
      accumulate_counters();
      history_counted = true;
      ok = check(CVodeReInit(s.cvode.get(), kink, s.y.get()), "CVodeReInit");
      if (ok) history_counted = false;
      ok = ok && check(CVodeSensReInit(s.cvode.get(), corrector, s.ys.get()), "CVodeSensReInit") && set_stop();
    }
    if (!ok || !advance(t)) {
      ok = false;
      break;
    }
    record(t, y, [&](int k) { return N_VGetArrayPointer(s.ys[k]); });
  }
  if (!history_counted) accumulate_counters();
  if (!ok) {
    if (!p->budget_failure.ok()) return p->budget_failure;
    return sundials::IntegratorFailure(absl::AbortedError(""), failure.empty() ? "sensitivity integration failed" : failure);
  }
  return spec::AnalysisFailure::Ok();
}

}  // namespace mbopt::lumped::sensitivity_internal
