#include "worker/multibody/forward_dynamics.h"

#include <idas/idas.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "worker/multibody/explicit_dynamics.h"
#include "worker/multibody/ggl_residual.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/parameter_derivatives.h"
#include "worker/multibody/integrator_setup.h"
#include "worker/sundials/sundials_handles.h"

namespace mbopt::multibody {
namespace {

using Eigen::Map;
using Eigen::VectorXd;

// What the residual callback needs; lives for one integration.
struct Problem {
  const ConstrainedSystem* system = nullptr;
  int n = 0, m = 0;
  const budget::AnalysisBudget* budget = nullptr;
  spec::AnalysisFailure budget_failure;  // why the budget stopped the integration
  std::string callback_failure;
  const std::vector<ParameterPerturbation>* parameters = nullptr;  // sensitivities, if any
  GglWorkspace work;
  Eigen::MatrixXd newton;
  // dF/dy (or, for a system without an exact state Jacobian, Phi_q) and M at
  // (state_jacobian_t, state_jacobian_at), for the sensitivity residuals.
  Eigen::MatrixXd state_jacobian, state_mass, state_phi_q;
  double state_jacobian_t = 0.0;
  VectorXd state_jacobian_at, state_jacobian_at_rates;
  // The sparse Newton matrix's pattern in compressed columns (KLU only).
  std::vector<sunindextype> column_starts, row_indices;
  // For the error weights (ErrorWeights): the integrator, the tolerances and
  // the first step, which IDAS has not taken when it first asks for them.
  void* ida = nullptr;
  double relative_tolerance = 0.0;
  const Eigen::VectorXd* absolute_tolerances = nullptr;
  double first_step = 0.0;
  // Per coordinate and velocity, the largest magnitude it has had at the
  // accepted steps so far (ErrorWeights).
  VectorXd peak_magnitudes;
  // The step-growth guard (LimitGrowthIfTrapped): counts at the start of
  // the current window, and when the growth was limited (negative: never).
  long window_steps = 0, window_error_test_failures = 0;
  double growth_limited_from_s = -1.0;
};

// Whether the analysis' budget stops the integration at t (and why, kept).
bool BudgetStops(Problem* p, double t) {
  if (p->budget == nullptr || !p->budget->Exhausted()) return false;
  p->budget_failure = p->budget->Check(t);
  return !p->budget_failure.ok();
}

int Residual(realtype t, N_Vector yy, N_Vector yp, N_Vector rr, void* user_data) {
  auto* p = static_cast<Problem*>(user_data);
  return sundials::GuardCallback(&p->callback_failure, "the residual", [&]() -> int {
    if (BudgetStops(p, t)) return -1;
    const int size = 2 * p->n + 2 * p->m;
    const Map<const VectorXd> y(N_VGetArrayPointer(yy), size);
    const Map<const VectorXd> y_dot(N_VGetArrayPointer(yp), size);
    Map<VectorXd> r(N_VGetArrayPointer(rr), size);
    return GglResidual(*p->system, t, y, y_dot, &p->work, r);
  });
}

// The exact Newton matrix into p->newton, for either storage below; the
// budget is checked here because forming it runs no residual.
int FormNewtonMatrix(Problem* p, realtype t, realtype cj, N_Vector yy, N_Vector yp) {
  if (BudgetStops(p, t)) return -1;
  const int size = 2 * p->n + 2 * p->m;
  const Map<const VectorXd> y(N_VGetArrayPointer(yy), size);
  const Map<const VectorXd> y_dot(N_VGetArrayPointer(yp), size);
  return GglNewtonMatrix(*p->system, t, cj, y, y_dot, &p->work, &p->newton);
}

int DenseNewtonMatrix(realtype t, realtype cj, N_Vector yy, N_Vector yp, N_Vector /*rr*/, SUNMatrix jac,
                      void* user_data, N_Vector, N_Vector, N_Vector) {
  auto* p = static_cast<Problem*>(user_data);
  return sundials::GuardCallback(&p->callback_failure, "the Newton matrix", [&]() -> int {
    if (int flag = FormNewtonMatrix(p, t, cj, yy, yp); flag != 0) return flag;
    const int size = 2 * p->n + 2 * p->m;
    // SUNDIALS' dense matrices are column-major like Eigen's.
    Map<Eigen::MatrixXd>(SUNDenseMatrix_Data(jac), size, size) = p->newton;
    return 0;
  });
}

// The same matrix in the compressed-column pattern built once per
// integration (KLU analyses it once and refactors with it); IDAS zeroes
// the matrix, indices included, before every call.
int SparseNewtonMatrix(realtype t, realtype cj, N_Vector yy, N_Vector yp, N_Vector /*rr*/, SUNMatrix jac,
                       void* user_data, N_Vector, N_Vector, N_Vector) {
  auto* p = static_cast<Problem*>(user_data);
  return sundials::GuardCallback(&p->callback_failure, "the Newton matrix", [&]() -> int {
    if (int flag = FormNewtonMatrix(p, t, cj, yy, yp); flag != 0) return flag;
    const int size = 2 * p->n + 2 * p->m;
    sunindextype* starts = SUNSparseMatrix_IndexPointers(jac);
    sunindextype* rows = SUNSparseMatrix_IndexValues(jac);
    realtype* values = SUNSparseMatrix_Data(jac);
    std::copy(p->column_starts.begin(), p->column_starts.end(), starts);
    std::copy(p->row_indices.begin(), p->row_indices.end(), rows);
    for (int col = 0; col < size; ++col) {
      for (sunindextype k = p->column_starts[static_cast<size_t>(col)];
           k < p->column_starts[static_cast<size_t>(col) + 1]; ++k) {
        values[k] = p->newton(p->row_indices[static_cast<size_t>(k)], col);
      }
    }
    return 0;
  });
}

// The system's validity bounds as IDAS root functions.
int ValidityBounds(realtype t, N_Vector yy, N_Vector /*yp*/, realtype* g, void* user_data) {
  auto* p = static_cast<Problem*>(user_data);
  return sundials::GuardCallback(&p->callback_failure, "the validity bounds", [&]() -> int {
    const Map<const VectorXd> y(N_VGetArrayPointer(yy), 2 * p->n + 2 * p->m);
    p->system->ValidityBounds(t, y.head(p->n), y.segment(p->n, p->n), g);
    return 0;
  });
}

// The sensitivity residuals F_y s_k + F_y' s_k' + F_p_k. F_y is the Newton
// matrix's at cj = 0 (exact, ggl_residual.h: d(M(q) v')/dq included) and
// F_y' s' = (s_q', M s_v', 0, 0) (F is linear in y'); both are formed once per
// state: IDAS's staggered corrector calls this again at the same (t, y) for
// every iteration of the sensitivities. F_p_k is exact where the parameter
// has a derivative model, else the central difference of the residual
// alone between the systems at p_k +- step_k, at the same state
// (parameter_derivatives.h). A system without an exact state Jacobian (a
// spatial one with bushings or rotational spring-dampers) gets F_y s_k from
// GglStateDirectionalDerivative instead: two
// residuals per parameter and call. The first version differenced the residual
// along (s, s') too (round-off then forced exact constraint rows by
// polarization of gamma): eight residuals per parameter and call, and the
// isolator's sensitivities cost 4.1 plain analyses at two parameters.
int SensitivityResidual(int count, realtype t, N_Vector yy, N_Vector yp, N_Vector /*rr*/, N_Vector* y_s,
                        N_Vector* yp_s, N_Vector* rr_s, void* user_data, N_Vector, N_Vector, N_Vector) {
  auto* p = static_cast<Problem*>(user_data);
  return sundials::GuardCallback(&p->callback_failure, "the sensitivity residual", [&]() -> int {
    const int n = p->n, size = 2 * n + 2 * p->m;
    const Map<const VectorXd> y(N_VGetArrayPointer(yy), size);
    const Map<const VectorXd> y_dot(N_VGetArrayPointer(yp), size);
    const bool analytic = p->system->has_exact_state_jacobian();
    // Keyed on y' too: the exact F_y holds d(M(q) v')/dq.
    if (!(p->state_jacobian_at.size() == size && p->state_jacobian_t == t && p->state_jacobian_at == y &&
          p->state_jacobian_at_rates == y_dot)) {
      if (analytic) {
        if (int flag = GglNewtonMatrix(*p->system, t, 0.0, y, y_dot, &p->work, &p->state_jacobian); flag != 0) {
          return flag;
        }
        p->state_mass = p->work.mass;
      } else {
        const VectorXd q = y.head(n);
        const ContinuedPastBounds continued(*p->system);
        if (int flag = p->system->MassMatrix(q, &p->state_mass); flag != 0) return flag;
        if (p->m > 0) {
          if (int flag = p->system->ConstraintJacobian(t, q, &p->state_phi_q); flag != 0) return flag;
        }
      }
      p->state_jacobian_t = t;
      p->state_jacobian_at = y;
      p->state_jacobian_at_rates = y_dot;
    }
    VectorXd partial(size);
    for (int k = 0; k < count; ++k) {
      const ParameterPerturbation& dp = (*p->parameters)[static_cast<size_t>(k)];
      const Map<const VectorXd> s(N_VGetArrayPointer(y_s[k]), size);
      const Map<const VectorXd> s_dot(N_VGetArrayPointer(yp_s[k]), size);
      Map<VectorXd> result(N_VGetArrayPointer(rr_s[k]), size);
      if (int flag = GglParameterDerivative(dp, t, y, y_dot, &p->work, partial); flag != 0) return flag;
      if (analytic) {
        result.noalias() = p->state_jacobian * s;
      } else if (int flag = GglStateDirectionalDerivative(*p->system, t, y, y_dot, s, p->state_phi_q, &p->work, result);
                 flag != 0) {
        return flag;
      }
      result.head(n) += s_dot.head(n);
      result.segment(n, n).noalias() += p->state_mass * s_dot.segment(n, n);
      result += partial;
    }
    return 0;
  });
}

// Newton's weight of a multiplier relative to the largest its effect gives:
// below 1 so that the weights, which IDAS computes once per step, still
// hold after it has cut the step (by 4 at a convergence failure) within it.
// 1 failed near the end of Andrews' mechanism at rtol 1e-10 (h cut to 1e-15
// s); 0.1 runs it from rtol 1e-4 to 1e-10 (docs/accuracy.md).
constexpr double kMultiplierWeightFactor = 0.1;

// The error weights: 1 / (rtol s_i + atol_i) for q and v, with
// s_i = max(|y_i|, kPeakMagnitudeFloor max|y_i|), the maximum over the
// accepted steps so far. IDAS's own rtol |y_i| collapses to atol whenever a
// coordinate or velocity passes through zero, and in a mechanism many do at
// once (a crank's nodes as it crosses the x axis: their y and x'): on the
// co-rotational elastic four-bar those components, held to 1e-9 against a
// normal 1e-6 |y|, had IDAS resolve the links' fast axial and bending
// vibrations at steps of 1e-6 s and order 1, rejecting two steps in three for
// 0.01 s after every crossing (6,989 steps, 4,591 rejected). The largest
// magnitude so far depends only on the accepted states, so the weights stay
// deterministic. A tenth, not the peak itself: rtol times the peak (2,457
// steps on the four-bar) loosened Andrews' mechanism at rtol 1e-10 from
// its published reference to 4.9e-8 rad (0.3: 1.8e-8; 0.1: within its test's
// 1e-8), as a motion that slows down keeps being held to its fastest
// speed; 0.01 took about as many steps on the four-bar as 0.1.
constexpr double kPeakMagnitudeFloor = 0.1;

// The error weights: q and v's as above (kPeakMagnitudeFloor); the
// multipliers' (algebraic, out of the error test, so only Newton's
// convergence test sees them) scaled to the step. Within a
// step of size h a correction d_lambda moves v by about h M^-1 Phi_q^T
// d_lambda and d_mu moves q by h Phi_q^T d_mu, so each multiplier is
// weighted by the largest weight its constraint row gives the coordinates it
// moves, times h. Fixed weights do not follow the step: the corrections of
// mu carry the round-off of Phi (about eps |q|) over h, those of lambda the
// round-off of v' = cj (v - v_predicted) over h, and at the first step of a
// fast start (h of 1e-13 s for Andrews' mechanism) that round-off alone
// failed Newton's test, at every smaller step IDAS then tried.
// The step-growth trap: IDAS doubles the step after an accepted one (its
// largest growth, 2), and on some stiff flexible mechanisms the doubled step
// fails the error test, the halved one passes, and the cycle repeats at
// order 1 with one rejection per accepted step, however small the accepted
// errors (docs/benchmarks.md: the co-rotational four-bar, 38,203 steps
// instead of some 2,800). A window of accepted steps with nearly as many
// error-test failures is that cycle and nothing else: a discontinuity costs
// a few failures while the step shrinks, not one per step for a whole window.
// Holding the growth to 1.5 breaks it. It stays held for the rest of the
// integration; a run that never cycles keeps IDAS's default to the bit.
constexpr long kGrowthWindowSteps = 32;
constexpr long kTrappedErrorTestFailures = 24;
constexpr double kTrappedGrowthLimit = 1.5;

void LimitGrowthIfTrapped(Problem* p) {
  if (p->growth_limited_from_s >= 0.0) return;
  long steps = 0, failures = 0;
  if (IDAGetNumSteps(p->ida, &steps) != IDA_SUCCESS || IDAGetNumErrTestFails(p->ida, &failures) != IDA_SUCCESS) {
    return;
  }
  if (steps - p->window_steps < kGrowthWindowSteps) return;
  if (failures - p->window_error_test_failures >= kTrappedErrorTestFailures) {
    realtype t = 0.0;
    if (IDASetEtaMax(p->ida, kTrappedGrowthLimit) == IDA_SUCCESS && IDAGetCurrentTime(p->ida, &t) == IDA_SUCCESS) {
      p->growth_limited_from_s = t;
    }
  }
  p->window_steps = steps;
  p->window_error_test_failures = failures;
}

int ErrorWeights(N_Vector yy, N_Vector ewt, void* user_data) {
  auto* p = static_cast<Problem*>(user_data);
  return sundials::GuardCallback(&p->callback_failure, "the error weights", [&]() -> int {
    const int n = p->n, m = p->m, size = 2 * n + 2 * m;
    const Map<const VectorXd> y(N_VGetArrayPointer(yy), size);
    Map<VectorXd> w(N_VGetArrayPointer(ewt), size);
    const VectorXd& atol = *p->absolute_tolerances;
    // IDAS asks for the weights once per step, before the step: the place to
    // watch its step control.
    LimitGrowthIfTrapped(p);
    if (p->peak_magnitudes.size() != 2 * n) p->peak_magnitudes = VectorXd::Zero(2 * n);
    for (int i = 0; i < 2 * n; ++i) {
      if (!std::isfinite(y[i])) return -1;
      const double magnitude = std::abs(y[i]);
      p->peak_magnitudes[i] = std::max(p->peak_magnitudes[i], magnitude);
      const double scale = std::max(magnitude, kPeakMagnitudeFloor * p->peak_magnitudes[i]);
      const double tolerance = p->relative_tolerance * scale + atol[i];
      if (!(tolerance > 0.0)) return -1;
      w[i] = 1.0 / tolerance;
    }
    if (m == 0) return 0;
    realtype h = 0.0, t = 0.0;
    // Before the first step IDAS has no step yet: the one it will take.
    if (IDAGetCurrentStep(p->ida, &h) != IDA_SUCCESS || h == 0.0) h = p->first_step;
    if (IDAGetCurrentTime(p->ida, &t) != IDA_SUCCESS) return -1;
    const VectorXd q = y.head(n);
    const ContinuedPastBounds continued(*p->system);
    if (p->system->MassMatrix(q, &p->work.mass) != 0 || p->system->ConstraintJacobian(t, q, &p->work.phi_q) != 0) {
      return -1;
    }
    const Eigen::ArrayXd q_weight = w.head(n).array();
    const Eigen::ArrayXd v_weight = w.segment(n, n).array() / p->work.mass.diagonal().array();
    const double scale = kMultiplierWeightFactor * std::abs(h);
    for (int j = 0; j < m; ++j) {
      const Eigen::ArrayXd row = p->work.phi_q.row(j).transpose().array().abs();
      w[2 * n + j] = scale * (row * v_weight).maxCoeff();
      w[2 * n + m + j] = scale * (row * q_weight).maxCoeff();
    }
    return w.allFinite() ? 0 : -1;
  });
}

void Accumulate(void* ida, ForwardDynamicsCounters* c) {
  long value = 0;
  if (IDAGetNumSteps(ida, &value) == IDA_SUCCESS) c->steps = value;
  if (IDAGetNumResEvals(ida, &value) == IDA_SUCCESS) c->residual_evaluations = value;
  if (IDAGetNumJacEvals(ida, &value) == IDA_SUCCESS) c->jacobian_evaluations = value;
  if (IDAGetNumLinResEvals(ida, &value) == IDA_SUCCESS) c->jacobian_residual_evaluations = value;
  if (IDAGetNumNonlinSolvIters(ida, &value) == IDA_SUCCESS) c->nonlinear_iterations = value;
  if (IDAGetNumErrTestFails(ida, &value) == IDA_SUCCESS) c->error_test_failures = value;
  if (IDAGetNumNonlinSolvConvFails(ida, &value) == IDA_SUCCESS) c->convergence_failures = value;
}

// Newton's convergence weight of the multipliers' sensitivities (see
// IntegrateForward), divided by the parameter's magnitude.
constexpr double kMuTolerance = 1e-3;

spec::AnalysisFailure Failed(spec::FailureKind kind, std::string reason) {
  return spec::AnalysisFailure::Of(kind, std::move(reason));
}

// (a0, lambda0) from [M Phi_q^T; Phi_q 0][a; lambda] = [Q; gamma] at a
// state consistent with the constraints.
spec::AnalysisFailure ConsistentAccelerations(const ConstrainedSystem& system, double t0, const VectorXd& q0,
                                              const VectorXd& v0, VectorXd* out) {
  const int n = system.num_coordinates(), m = system.num_constraints();
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
  *out = lu.solve(rhs);
  return spec::AnalysisFailure::Ok();
}

// What to try after IDAS gave up (its flag) at (t, q) on the way from t0 to
// `target`: the joint whose constraint rows are nearest to dependent there
// (the largest entry of Phi_q's left singular vector of its smallest
// singular value: where a mechanism locks) with that value over the largest
// (near 0: a singular position), and the settings to change. The stabilized
// form passes through the singular positions tried (a slider-crank with rod
// and crank of one length, a mass on two crossing lines), so no advice is
// keyed to the ratio.
std::string FailureAdvice(const ConstrainedSystem& system, int flag, double t0, double t, double target,
                          const VectorXd& q, const ForwardDynamicsOptions& options, double first_step) {
  std::string advice;
  const int m = system.num_constraints();
  double conditioning = 1.0;
  Eigen::MatrixXd phi_q;
  if (m > 0 && system.ConstraintJacobian(t, q, &phi_q) == 0 && phi_q.allFinite()) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(phi_q, Eigen::ComputeFullU);
    const VectorXd& sigma = svd.singularValues();
    if (sigma.size() > 0 && sigma[0] > 0.0) conditioning = sigma[sigma.size() - 1] / sigma[0];
    Eigen::Index row = 0;
    svd.matrixU().col(svd.matrixU().cols() - 1).cwiseAbs().maxCoeff(&row);
    // Only a mechanism names its rows (a system written in code for a test
    // has no joints).
    const auto* mechanism = dynamic_cast<const Mechanism*>(&system);
    if (mechanism != nullptr) {
      const int r = static_cast<int>(row);
      advice += absl::StrFormat(
          "; the constraint rows nearest to dependent there are those of joint '%s'%s (smallest singular value of the "
          "constraint Jacobian %.2g of the largest)",
          mechanism->model().joints[static_cast<size_t>(mechanism->joint_of_row(r))].name,
          mechanism->is_driver_row(r) ? "'s driver" : "", conditioning);
    }
  }
  // The coordinates are known to round-off, eps |q|: an absolute tolerance
  // within 1e3 of it leaves Newton's corrections no room.
  const double round_off = std::numeric_limits<double>::epsilon() * std::max(1.0, MaxAbs(q));
  // Failures within the first 1e-3 of the way from t0 to the instant IDAS
  // was heading for are the start's (its first step comes from the initial
  // accelerations).
  constexpr double kStartFraction = 1e-3;
  std::vector<std::string> tries;
  if (options.absolute_tolerance < 1e3 * round_off) {
    tries.push_back(absl::StrFormat("a looser absolute_tolerance (now %.3g, near the coordinates' round-off %.2g)",
                                    options.absolute_tolerance, round_off));
  }
  if (t - t0 <= kStartFraction * (target - t0)) {
    tries.push_back(absl::StrFormat(
        "at the start (first step %.3g s, from the initial accelerations over the tolerances): check that the "
        "initial rates and poses are meant, or loosen absolute_tolerance so that the first step can grow",
        first_step));
  }
  if (flag == IDA_TOO_MUCH_WORK) {
    tries.push_back(absl::StrFormat("a larger integrator max_steps (now %d)", static_cast<int>(options.max_steps)));
  }
  tries.push_back(absl::StrFormat("integrator { relative_tolerance absolute_tolerance } looser than now (%.3g, %.3g)",
                                  options.relative_tolerance, options.absolute_tolerance));
  advice += "; try: ";
  for (size_t k = 0; k < tries.size(); ++k) advice += (k > 0 ? "; or " : "") + tries[k];
  return advice;
}

}  // namespace

spec::AnalysisFailure IntegrateForward(const ConstrainedSystem& system, double t0, const VectorXd& q0,
                                       const VectorXd& v0, const std::vector<double>& times,
                                       const ForwardDynamicsOptions& options, const MotionCallback& at_instant,
                                       ForwardDynamicsCounters* counters,
                                       const ForwardSensitivityInput* sensitivities) {
  if (options.method == ForwardDynamicsOptions::Method::kExplicitRungeKutta) {
    if (sensitivities != nullptr && !sensitivities->parameters.empty()) {
      return Failed(spec::FailureKind::kInvalidModel,
                    "the explicit Runge-Kutta integrator carries no simulator sensitivities: use integrator "
                    "{ method: IDAS } (the default) for a study with simulator sensitivities");
    }
    return IntegrateForwardExplicit(system, t0, q0, v0, times, options, at_instant, counters);
  }
  Problem p;
  p.system = &system;
  p.n = system.num_coordinates();
  p.m = system.num_constraints();
  p.budget = options.budget;
  const int n = p.n, m = p.m, size = 2 * n + 2 * m;
  if (q0.size() != n || v0.size() != n) {
    return Failed(spec::FailureKind::kInvalidModel, "initial coordinates of the wrong size");
  }

  // Consistent accelerations and multipliers at t0.
  VectorXd accelerations_multipliers;
  if (spec::AnalysisFailure f = ConsistentAccelerations(system, t0, q0, v0, &accelerations_multipliers); !f.ok()) {
    return f;
  }

  SundialsCalls check;
  struct Handles {
    sundials::Context context;
    sundials::Vector yy, yp, id, atol;
    sundials::Matrix matrix;
    sundials::LinearSolver linear_solver;
    sundials::Memory<&IDAFree> ida;
  } h;
  if (spec::AnalysisFailure f = CreateContextAndVectors(size, &h.context, {&h.yy, &h.yp, &h.id, &h.atol}); !f.ok()) {
    return f;
  }
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
  // Newton's convergence test and are scaled to the step (ErrorWeights), so
  // only q and v have absolute tolerances.
  Map<VectorXd> atol(N_VGetArrayPointer(h.atol.get()), size);
  atol.setZero();
  atol.head(2 * n).setConstant(options.absolute_tolerance);
  const bool analytic = system.has_analytic_derivatives();
  const bool sparse =
      analytic && (options.linear_solver == ForwardDynamicsOptions::LinearSolver::kSparse ||
                   (options.linear_solver == ForwardDynamicsOptions::LinearSolver::kAutomatic &&
                    size >= ForwardDynamicsOptions::kSparseFromUnknowns));
  counters->sparse_linear_solver = sparse;
  if (sparse) {
    const ConstrainedSystem::Pattern pattern = GglNewtonPattern(system);
    p.column_starts.assign(1, 0);
    for (int col = 0; col < size; ++col) {
      for (int row = 0; row < size; ++row) {
        if (pattern(row, col)) p.row_indices.push_back(row);
      }
      p.column_starts.push_back(static_cast<sunindextype>(p.row_indices.size()));
    }
    h.matrix.reset(SUNSparseMatrix(size, size, static_cast<sunindextype>(p.row_indices.size()), CSC_MAT,
                                   h.context.get()));
    if (!h.matrix) return Failed(spec::FailureKind::kIntegrator, "SUNSparseMatrix failed");
    h.linear_solver.reset(SUNLinSol_KLU(h.yy.get(), h.matrix.get(), h.context.get()));
  } else {
    h.matrix.reset(SUNDenseMatrix(size, size, h.context.get()));
    if (!h.matrix) return Failed(spec::FailureKind::kIntegrator, "SUNDenseMatrix failed");
    h.linear_solver.reset(SUNLinSol_Dense(h.yy.get(), h.matrix.get(), h.context.get()));
  }
  h.ida.reset(IDACreate(h.context.get()));
  if (!h.linear_solver || !h.ida) return Failed(spec::FailureKind::kIntegrator, "SUNDIALS allocation failed");
  void* ida = h.ida.get();
  p.ida = ida;
  p.relative_tolerance = options.relative_tolerance;
  const VectorXd absolute_tolerances = atol;
  p.absolute_tolerances = &absolute_tolerances;
  // IDAS's own rule for the first step (0.001 of the way to the first
  // instant, at most 0.5 over the weighted norm of y'0 without the
  // multipliers), made explicit so that the first step's weights know it.
  {
    const auto first_instant = std::find_if(times.begin(), times.end(), [&](double t) { return t > t0; });
    double first = first_instant == times.end() ? 0.0 : 0.001 * (*first_instant - t0);
    double squares = 0.0;
    for (int i = 0; i < 2 * n; ++i) {
      const double weighted = y_dot[i] / (options.relative_tolerance * std::abs(y[i]) + atol[i]);
      squares += weighted * weighted;
    }
    const double y_dot_norm = std::sqrt(squares / size);
    if (y_dot_norm * first > 0.5) first = 0.5 / y_dot_norm;
    if (options.max_step_size > 0.0) first = std::min(first, options.max_step_size);
    p.first_step = first;
  }
  bool ok = check(IDASetErrHandlerFn(ida, &sundials::CaptureMessage, check.message_sink()), "IDASetErrHandlerFn") &&
            check(IDAInit(ida, &Residual, t0, h.yy.get(), h.yp.get()), "IDAInit") &&
            check(IDASetUserData(ida, &p), "IDASetUserData") &&
            check(IDAWFtolerances(ida, &ErrorWeights), "IDAWFtolerances") &&
            check(IDASetLinearSolver(ida, h.linear_solver.get(), h.matrix.get()), "IDASetLinearSolver") &&
            (!analytic ||
             check(IDASetJacFn(ida, sparse ? &SparseNewtonMatrix : &DenseNewtonMatrix), "IDASetJacFn")) &&
            check(IDASetId(ida, h.id.get()), "IDASetId") &&
            check(IDASetSuppressAlg(ida, SUNTRUE), "IDASetSuppressAlg") &&
            check(IDASetMaxNumSteps(ida, options.max_steps), "IDASetMaxNumSteps") &&
            (p.first_step <= 0.0 || check(IDASetInitStep(ida, p.first_step), "IDASetInitStep")) &&
            (options.max_step_size <= 0.0 || check(IDASetMaxStep(ida, options.max_step_size), "IDASetMaxStep"));
  if (!ok) return check.Failure();

  // A table that ends at the last instant (a tabulated driver up to the time
  // grid's end): IDAS would step past it and interpolate back, and the
  // equations are not defined there.
  const double defined_until = system.DefinedUntil_s();
  if (std::isfinite(defined_until) && !times.empty() &&
      !check(IDASetStopTime(ida, std::min(defined_until, times.back())), "IDASetStopTime")) {
    return check.Failure();
  }

  // Validity bounds: a start outside is a failure at t0; a crossing later
  // is an event that ends the integration there (only crossings downwards,
  // from valid to invalid, count).
  const int num_bounds = system.num_validity_bounds();
  std::vector<int> bounds_crossed(static_cast<size_t>(num_bounds), 0);
  if (num_bounds > 0) {
    if (spec::AnalysisFailure f = ValidityBoundsHoldAtStart(system, t0, q0, v0); !f.ok()) return f;
    std::vector<int> downwards(static_cast<size_t>(num_bounds), -1);
    ok = check(IDARootInit(ida, num_bounds, &ValidityBounds), "IDARootInit") &&
         check(IDASetRootDirection(ida, downwards.data()), "IDASetRootDirection") &&
         check(IDASetNoInactiveRootWarn(ida), "IDASetNoInactiveRootWarn");
    if (!ok) return check.Failure();
  }

  // Sensitivities: initial values by central differences of the consistent
  // start along (dq0/dp_k, dv0/dp_k, e_k).
  const int num_sens = sensitivities != nullptr ? static_cast<int>(sensitivities->parameters.size()) : 0;
  sundials::VectorArray y_s, yp_s, atol_s;
  if (num_sens > 0) {
    p.parameters = &sensitivities->parameters;
    y_s = sundials::VectorArray(N_VCloneVectorArray(num_sens, h.yy.get()), num_sens);
    yp_s = sundials::VectorArray(N_VCloneVectorArray(num_sens, h.yy.get()), num_sens);
    atol_s = sundials::VectorArray(N_VCloneVectorArray(num_sens, h.yy.get()), num_sens);
    if (!y_s || !yp_s || !atol_s) return Failed(spec::FailureKind::kIntegrator, "SUNDIALS allocation failed");
    for (int k = 0; k < num_sens; ++k) {
      const ParameterPerturbation& dp = sensitivities->parameters[static_cast<size_t>(k)];
      const VectorXd& dq = sensitivities->q0[static_cast<size_t>(k)];
      const VectorXd& dv = sensitivities->v0[static_cast<size_t>(k)];
      VectorXd plus, minus;
      if (spec::AnalysisFailure f =
              ConsistentAccelerations(*dp.plus, t0, q0 + dp.step * dq, v0 + dp.step * dv, &plus);
          !f.ok()) {
        return f;
      }
      if (spec::AnalysisFailure f =
              ConsistentAccelerations(*dp.minus, t0, q0 - dp.step * dq, v0 - dp.step * dv, &minus);
          !f.ok()) {
        return f;
      }
      const VectorXd d_accelerations_multipliers = (plus - minus) / (2.0 * dp.step);
      Map<VectorXd> s0(N_VGetArrayPointer(y_s[k]), size), sp0(N_VGetArrayPointer(yp_s[k]), size),
          tol(N_VGetArrayPointer(atol_s[k]), size);
      s0.setZero();
      sp0.setZero();
      s0.head(n) = dq;
      s0.segment(n, n) = dv;
      if (m > 0) s0.segment(2 * n, m) = d_accelerations_multipliers.tail(m);
      sp0.head(n) = dv;
      sp0.segment(n, n) = d_accelerations_multipliers.head(n);
      // The multipliers' sensitivities only enter Newton's convergence test
      // (they are algebraic). Their residuals, central differences of force
      // rows, carry round-off of order 1e-16 |F| / step; weighted like the
      // coordinates (1e-10 / |p|) the corrector fails on it at once (seen on
      // the isolator), so they get mu's weight.
      tol.head(2 * n) = atol.head(2 * n) / dp.magnitude;
      tol.tail(2 * m).setConstant(kMuTolerance / dp.magnitude);
    }
    ok = check(IDASensInit(ida, num_sens, IDA_STAGGERED, &SensitivityResidual, y_s.get(), yp_s.get()),
               "IDASensInit") &&
         check(IDASensSVtolerances(ida, options.relative_tolerance, atol_s.get()), "IDASensSVtolerances") &&
         check(IDASetSensErrCon(ida, SUNTRUE), "IDASetSensErrCon");
    if (!ok) return check.Failure();
  }

  VectorXd phi, phi_t;
  Eigen::MatrixXd phi_q;
  double t_reached = t0;
  for (double t : times) {
    if (t > t_reached) {
      const int flag = IDASolve(ida, t, &t_reached, h.yy.get(), h.yp.get(), IDA_NORMAL);
      Accumulate(ida, counters);
      counters->step_growth_limited_from_s = p.growth_limited_from_s;
      if (flag < 0) {
        if (!system.FailureReason().empty()) {
          return Failed(spec::FailureKind::kModelValidity,
                        absl::StrFormat("%s; the integrator gave up near t = %.6g s", system.FailureReason(), t_reached));
        }
        if (!p.budget_failure.ok()) return p.budget_failure;
        const std::string callback = p.callback_failure.empty() ? "" : " [" + p.callback_failure + "]";
        return Failed(spec::FailureKind::kIntegrator,
                      absl::StrFormat("the integrator failed near t = %.6g s (target %.6g s): %s%s%s", t_reached, t,
                                      check.message(), callback,
                                      FailureAdvice(system, flag, t0, t_reached, t, y.head(n), options, p.first_step)));
      }
      if (flag == IDA_ROOT_RETURN) {
        if (!check(IDAGetRootInfo(ida, bounds_crossed.data()), "IDAGetRootInfo")) {
          return check.Failure();
        }
        const int k = static_cast<int>(std::find(bounds_crossed.begin(), bounds_crossed.end(), -1) -
                                       bounds_crossed.begin());
        const VectorXd q = y.head(n), v = y.segment(n, n);
        return Failed(spec::FailureKind::kModelValidity, system.BoundReason(k < num_bounds ? k : 0, t_reached, q, v));
      }
      if (t_reached < t) {
        // Stopped at the end of a table that does not reach the instant (a
        // scene loader refuses such a table; a model built in code may not).
        return Failed(spec::FailureKind::kModelValidity,
                      absl::StrFormat("a tabulated profile ends at t = %.6g s, before the instant t = %.6g s",
                                      t_reached, t));
      }
    }
    MotionSample sample;
    sample.t_s = t;
    sample.q = y.head(n);
    sample.v = y.segment(n, n);
    sample.a = y_dot.segment(n, n);
    sample.lambda = y.segment(2 * n, m);
    if (num_sens > 0) {
      realtype t_sens = t;
      // Before the first step y_s and yp_s still hold the initial values
      // (and IDAS has no interpolant yet).
      if (t > t0 && (!check(IDAGetSens(ida, &t_sens, y_s.get()), "IDAGetSens") ||
                     !check(IDAGetSensDky(ida, t, 1, yp_s.get()), "IDAGetSensDky"))) {
        return check.Failure();
      }
      sample.sensitivities.resize(static_cast<size_t>(num_sens));
      for (int k = 0; k < num_sens; ++k) {
        const Map<const VectorXd> s_k(N_VGetArrayPointer(y_s[k]), size), sp_k(N_VGetArrayPointer(yp_s[k]), size);
        StateSensitivity& out = sample.sensitivities[static_cast<size_t>(k)];
        out.q = s_k.head(n);
        out.v = s_k.segment(n, n);
        out.a = sp_k.segment(n, n);
        out.lambda = s_k.segment(2 * n, m);
      }
    }
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
  counters->step_growth_limited_from_s = p.growth_limited_from_s;
  return spec::AnalysisFailure::Ok();
}

}  // namespace mbopt::multibody
