#include "worker/multibody/forward_dynamics.h"

#include <idas/idas.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "worker/multibody/ggl_residual.h"
#include "worker/multibody/parameter_derivatives.h"
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
  // dF/dy and M at (state_jacobian_t, state_jacobian_at), for the
  // sensitivity residuals.
  Eigen::MatrixXd state_jacobian, state_mass;
  double state_jacobian_t = 0.0;
  VectorXd state_jacobian_at;
  // The sparse Newton matrix's pattern in compressed columns (KLU only).
  std::vector<sunindextype> column_starts, row_indices;
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
int FormNewtonMatrix(Problem* p, realtype t, realtype cj, N_Vector yy) {
  if (BudgetStops(p, t)) return -1;
  const int size = 2 * p->n + 2 * p->m;
  const Map<const VectorXd> y(N_VGetArrayPointer(yy), size);
  return GglNewtonMatrix(*p->system, t, cj, y, &p->work, &p->newton);
}

int DenseNewtonMatrix(realtype t, realtype cj, N_Vector yy, N_Vector /*yp*/, N_Vector /*rr*/, SUNMatrix jac,
                      void* user_data, N_Vector, N_Vector, N_Vector) {
  auto* p = static_cast<Problem*>(user_data);
  return sundials::GuardCallback(&p->callback_failure, "the Newton matrix", [&]() -> int {
    if (int flag = FormNewtonMatrix(p, t, cj, yy); flag != 0) return flag;
    const int size = 2 * p->n + 2 * p->m;
    // SUNDIALS' dense matrices are column-major like Eigen's.
    Map<Eigen::MatrixXd>(SUNDenseMatrix_Data(jac), size, size) = p->newton;
    return 0;
  });
}

// The same matrix in the compressed-column pattern built once per
// integration (KLU analyses it once and refactors with it); IDAS zeroes
// the matrix, indices included, before every call.
int SparseNewtonMatrix(realtype t, realtype cj, N_Vector yy, N_Vector /*yp*/, N_Vector /*rr*/, SUNMatrix jac,
                       void* user_data, N_Vector, N_Vector, N_Vector) {
  auto* p = static_cast<Problem*>(user_data);
  return sundials::GuardCallback(&p->callback_failure, "the Newton matrix", [&]() -> int {
    if (int flag = FormNewtonMatrix(p, t, cj, yy); flag != 0) return flag;
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
// matrix's at cj = 0 (exact, ggl_residual.h) and F_y' s' = (s_q', M s_v',
// 0, 0) (F is linear in y' and M is constant); both are formed once per
// state: IDAS's staggered corrector calls this again at the same (t, y) for
// every iteration of the sensitivities. F_p_k is exact where the parameter
// has a derivative model, else the central difference of the residual
// alone between the systems at p_k +- step_k, at the same state
// (parameter_derivatives.h). The first version differenced the residual
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
    if (!(p->state_jacobian_at.size() == size && p->state_jacobian_t == t && p->state_jacobian_at == y)) {
      if (int flag = GglNewtonMatrix(*p->system, t, 0.0, y, &p->work, &p->state_jacobian); flag != 0) return flag;
      p->state_mass = p->work.mass;
      p->state_jacobian_t = t;
      p->state_jacobian_at = y;
    }
    VectorXd partial(size);
    for (int k = 0; k < count; ++k) {
      const ParameterPerturbation& dp = (*p->parameters)[static_cast<size_t>(k)];
      const Map<const VectorXd> s(N_VGetArrayPointer(y_s[k]), size);
      const Map<const VectorXd> s_dot(N_VGetArrayPointer(yp_s[k]), size);
      Map<VectorXd> result(N_VGetArrayPointer(rr_s[k]), size);
      if (int flag = GglParameterDerivative(dp, t, y, y_dot, &p->work, partial); flag != 0) return flag;
      result.noalias() = p->state_jacobian * s;
      result.head(n) += s_dot.head(n);
      result.segment(n, n).noalias() += p->state_mass * s_dot.segment(n, n);
      result += partial;
    }
    return 0;
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

// Newton's convergence weight of the stabilizing multipliers mu (see
// IntegrateForward).
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

}  // namespace

spec::AnalysisFailure IntegrateForward(const ConstrainedSystem& system, double t0, const VectorXd& q0,
                                       const VectorXd& v0, const std::vector<double>& times,
                                       const ForwardDynamicsOptions& options, const MotionCallback& at_instant,
                                       ForwardDynamicsCounters* counters,
                                       const ForwardSensitivityInput* sensitivities) {
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

  struct Handles {
    sundials::Context context;
    sundials::Vector yy, yp, id, atol;
    sundials::Matrix matrix;
    sundials::LinearSolver linear_solver;
    sundials::Memory<&IDAFree> ida;
  } h;
  std::string sundials_message;
  h.context = sundials::MakeContext();
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
  auto check = [&](int flag, const char* call) {
    if (flag >= 0) return true;
    sundials_message = absl::StrFormat("%s failed (%d)%s%s", call, flag, sundials_message.empty() ? "" : ": ",
                                       sundials_message);
    return false;
  };
  bool ok = check(IDASetErrHandlerFn(ida, &sundials::CaptureMessage, &sundials_message), "IDASetErrHandlerFn") &&
            check(IDAInit(ida, &Residual, t0, h.yy.get(), h.yp.get()), "IDAInit") &&
            check(IDASetUserData(ida, &p), "IDASetUserData") &&
            check(IDASVtolerances(ida, options.relative_tolerance, h.atol.get()), "IDASVtolerances") &&
            check(IDASetLinearSolver(ida, h.linear_solver.get(), h.matrix.get()), "IDASetLinearSolver") &&
            (!analytic ||
             check(IDASetJacFn(ida, sparse ? &SparseNewtonMatrix : &DenseNewtonMatrix), "IDASetJacFn")) &&
            check(IDASetId(ida, h.id.get()), "IDASetId") &&
            check(IDASetSuppressAlg(ida, SUNTRUE), "IDASetSuppressAlg") &&
            check(IDASetMaxNumSteps(ida, options.max_steps), "IDASetMaxNumSteps") &&
            (options.max_step_size <= 0.0 || check(IDASetMaxStep(ida, options.max_step_size), "IDASetMaxStep"));
  if (!ok) return Failed(spec::FailureKind::kIntegrator, sundials_message);

  // A table that ends at the last instant (a tabulated driver up to the time
  // grid's end): IDAS would step past it and interpolate back, and the
  // equations are not defined there.
  const double defined_until = system.DefinedUntil_s();
  if (std::isfinite(defined_until) && !times.empty() &&
      !check(IDASetStopTime(ida, std::min(defined_until, times.back())), "IDASetStopTime")) {
    return Failed(spec::FailureKind::kIntegrator, sundials_message);
  }

  // Validity bounds: a start outside is a failure at t0; a crossing later
  // is an event that ends the integration there (only crossings downwards,
  // from valid to invalid, count).
  const int num_bounds = system.num_validity_bounds();
  std::vector<int> bounds_crossed(static_cast<size_t>(num_bounds), 0);
  if (num_bounds > 0) {
    std::vector<double> g(static_cast<size_t>(num_bounds));
    system.ValidityBounds(t0, q0, v0, g.data());
    for (int k = 0; k < num_bounds; ++k) {
      if (!(g[static_cast<size_t>(k)] >= 0.0)) {
        return Failed(spec::FailureKind::kModelValidity, system.BoundReason(k, t0, q0, v0));
      }
    }
    std::vector<int> downwards(static_cast<size_t>(num_bounds), -1);
    ok = check(IDARootInit(ida, num_bounds, &ValidityBounds), "IDARootInit") &&
         check(IDASetRootDirection(ida, downwards.data()), "IDASetRootDirection") &&
         check(IDASetNoInactiveRootWarn(ida), "IDASetNoInactiveRootWarn");
    if (!ok) return Failed(spec::FailureKind::kIntegrator, sundials_message);
  }

  // Sensitivities: initial values by central differences of the consistent
  // start along (dq0/dp_k, dv0/dp_k, e_k).
  const int num_sens = sensitivities != nullptr ? static_cast<int>(sensitivities->parameters.size()) : 0;
  sundials::VectorArray y_s, yp_s, atol_s;
  if (num_sens > 0) {
    // The sensitivity residuals are formed from the Newton matrix's
    // derivatives.
    if (!analytic) {
      return Failed(spec::FailureKind::kInvalidModel,
                    "forward sensitivities need a system with analytic derivatives (ConstrainedSystem::"
                    "has_analytic_derivatives)");
    }
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
    if (!ok) return Failed(spec::FailureKind::kIntegrator, sundials_message);
  }

  VectorXd phi, phi_t;
  Eigen::MatrixXd phi_q;
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
        if (!p.budget_failure.ok()) return p.budget_failure;
        return Failed(spec::FailureKind::kIntegrator,
                      absl::StrFormat("the integrator failed near t = %.6g s (target %.6g s): %s%s", t_reached, t,
                                      sundials_message, p.callback_failure.empty() ? "" : " [" + p.callback_failure + "]"));
      }
      if (flag == IDA_ROOT_RETURN) {
        if (!check(IDAGetRootInfo(ida, bounds_crossed.data()), "IDAGetRootInfo")) {
          return Failed(spec::FailureKind::kIntegrator, sundials_message);
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
        return Failed(spec::FailureKind::kIntegrator, sundials_message);
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
  return spec::AnalysisFailure::Ok();
}

}  // namespace mbopt::multibody
