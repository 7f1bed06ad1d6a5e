#include "worker/multibody/static_equilibrium.h"

#include <kinsol/kinsol.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>

#include "absl/strings/str_format.h"
#include "worker/solve/sundials_handles.h"

namespace mbopt::multibody {
namespace {

using Eigen::Map;
using Eigen::MatrixXd;
using Eigen::VectorXd;

// What the residual callback needs; lives for one analysis.
struct Problem {
  const ConstrainedSystem* system = nullptr;
  int n = 0, m = 0;
  double t = 0.0;
  std::int64_t evaluations = 0;
  std::string callback_failure;
  VectorXd zero_velocity, forces, phi;
  MatrixXd phi_q;
};

// F(q, lambda) = (Q(t, q, 0) - Phi_q^T lambda, Phi(t, q)).
int Evaluate(Problem* p, const VectorXd& x, VectorXd* f) {
  ++p->evaluations;
  const int n = p->n, m = p->m;
  const VectorXd q = x.head(n);
  const ConstrainedSystem& s = *p->system;
  int flag = s.AppliedForces(p->t, q, p->zero_velocity, &p->forces);
  if (flag == 0 && m > 0) flag = s.ConstraintJacobian(p->t, q, &p->phi_q);
  if (flag == 0 && m > 0) flag = s.Constraints(p->t, q, &p->phi);
  if (flag != 0) return flag;
  f->resize(n + m);
  f->head(n) = p->forces;
  if (m > 0) {
    f->head(n) -= p->phi_q.transpose() * x.tail(m);
    f->tail(m) = p->phi;
  }
  return f->allFinite() ? 0 : 1;
}

int Residual(N_Vector uu, N_Vector ff, void* user_data) {
  auto* p = static_cast<Problem*>(user_data);
  try {
    const int size = p->n + p->m;
    const VectorXd x = Map<const VectorXd>(N_VGetArrayPointer(uu), size);
    VectorXd f;
    const int flag = Evaluate(p, x, &f);
    if (flag != 0) return flag;
    Map<VectorXd>(N_VGetArrayPointer(ff), size) = f;
    return 0;
  } catch (const std::exception& e) {
    p->callback_failure = e.what();
    return -1;
  } catch (...) {
    p->callback_failure = "unknown exception in the residual";
    return -1;
  }
}

spec::AnalysisFailure Failed(spec::FailureKind kind, std::string reason) {
  return spec::AnalysisFailure::Of(kind, std::move(reason));
}

// dF/dq at a solution by central differences (only the force rows are
// needed: the stiffness).
bool Stiffness(Problem* p, const VectorXd& x, MatrixXd* k) {
  const int n = p->n;
  k->resize(n, n);
  VectorXd xp = x, f_plus, f_minus;
  for (int i = 0; i < n; ++i) {
    const double h = 1e-6 * std::max(1.0, std::abs(x[i]));
    xp[i] = x[i] + h;
    if (Evaluate(p, xp, &f_plus) != 0) return false;
    xp[i] = x[i] - h;
    if (Evaluate(p, xp, &f_minus) != 0) return false;
    xp[i] = x[i];
    k->col(i) = (f_plus.head(n) - f_minus.head(n)) / (2 * h);
  }
  return true;
}

// The smallest eigenvalue of the reduced tangent stiffness, relative to the
// largest in magnitude; +1 when no direction is free.
double RelativeLeastStiffness(Problem* p, const VectorXd& x, bool* ok) {
  *ok = true;
  const int n = p->n;
  MatrixXd null_space = MatrixXd::Identity(n, n);
  if (p->m > 0) {
    Evaluate(p, x, &p->forces);  // refreshes p->phi_q at x
    Eigen::ColPivHouseholderQR<MatrixXd> qr(p->phi_q.transpose());
    qr.setThreshold(1e-9);
    qr.compute(p->phi_q.transpose());
    const int rank = static_cast<int>(qr.rank());
    if (rank >= n) return 1.0;
    const MatrixXd basis = qr.householderQ();
    null_space = basis.rightCols(n - rank);
  }
  MatrixXd dfdq;
  if (!Stiffness(p, x, &dfdq)) {
    *ok = false;
    return 0.0;
  }
  // Tangent stiffness K = -dF/dq (F is the out-of-balance force).
  const MatrixXd k = -0.5 * (dfdq + dfdq.transpose());
  const MatrixXd reduced = null_space.transpose() * k * null_space;
  Eigen::SelfAdjointEigenSolver<MatrixXd> eig(reduced, Eigen::EigenvaluesOnly);
  const VectorXd values = eig.eigenvalues();
  const double largest = MaxAbs(values);
  if (!(largest > 0.0)) return 0.0;
  return values.minCoeff() / largest;
}

}  // namespace

spec::AnalysisFailure RunStaticEquilibrium(const ConstrainedSystem& system, const VectorXd& q0,
                                           const std::vector<double>& times, const StaticOptions& options,
                                           const MotionCallback& at_instant, StaticCounters* counters) {
  namespace sd = solve::sundials;
  Problem p;
  p.system = &system;
  p.n = system.num_coordinates();
  p.m = system.num_constraints();
  const int n = p.n, m = p.m, size = n + m;
  if (q0.size() != n) return Failed(spec::FailureKind::kInvalidModel, "initial coordinates of the wrong size");
  if (times.empty()) return spec::AnalysisFailure::Ok();
  p.zero_velocity = VectorXd::Zero(n);
  p.t = times.front();

  // Start: the assembled positions, multipliers by least squares, and the
  // scale of the force rows from the applied forces there.
  VectorXd x(size);
  x.head(n) = q0;
  if (system.AppliedForces(p.t, q0, p.zero_velocity, &p.forces) != 0 || !p.forces.allFinite()) {
    return Failed(spec::FailureKind::kNonFiniteValue,
                  absl::StrFormat("the applied forces are not finite at the start (t = %.6g s)", p.t));
  }
  if (m > 0) {
    system.ConstraintJacobian(p.t, q0, &p.phi_q);
    x.tail(m) = p.phi_q.transpose().completeOrthogonalDecomposition().solve(p.forces);
  }
  const double force_scale = std::max(1.0, MaxAbs(p.forces));

  sd::Context context = sd::MakeContext();
  if (!context) return Failed(spec::FailureKind::kIntegrator, "KINSOL: no SUNDIALS context");
  sd::Vector u(N_VNew_Serial(size, context.get()));
  sd::Vector u_scale(N_VNew_Serial(size, context.get()));
  sd::Vector f_scale(N_VNew_Serial(size, context.get()));
  sd::Matrix jacobian(SUNDenseMatrix(size, size, context.get()));
  if (!u || !u_scale || !f_scale || !jacobian) return Failed(spec::FailureKind::kIntegrator, "KINSOL: out of memory");
  sd::LinearSolver solver(SUNLinSol_Dense(u.get(), jacobian.get(), context.get()));
  sd::Memory<KINFree> kinsol(KINCreate(context.get()));
  if (!solver || !kinsol) return Failed(spec::FailureKind::kIntegrator, "KINSOL: out of memory");
  std::string message;
  N_VConst(1.0, u_scale.get());
  Map<VectorXd> fs(N_VGetArrayPointer(f_scale.get()), size);
  fs.head(n).setConstant(1.0 / force_scale);
  fs.tail(m).setConstant(1.0);
  void* mem = kinsol.get();
  if (KINInit(mem, Residual, u.get()) != KIN_SUCCESS || KINSetUserData(mem, &p) != KIN_SUCCESS ||
      KINSetErrHandlerFn(mem, sd::CaptureMessage, &message) != KIN_SUCCESS ||
      KINSetLinearSolver(mem, solver.get(), jacobian.get()) != KIN_SUCCESS ||
      // A fresh Jacobian every iteration: plain Newton, quadratic near the
      // solution; the systems are small.
      KINSetMaxSetupCalls(mem, 1) != KIN_SUCCESS || KINSetFuncNormTol(mem, options.tolerance) != KIN_SUCCESS ||
      KINSetScaledStepTol(mem, 1e-15) != KIN_SUCCESS ||
      KINSetNumMaxIters(mem, options.max_iterations) != KIN_SUCCESS) {
    return Failed(spec::FailureKind::kIntegrator, "KINSOL set-up failed: " + message);
  }

  Map<VectorXd> u_values(N_VGetArrayPointer(u.get()), size);
  u_values = x;
  MotionSample sample;
  sample.v = VectorXd::Zero(n);
  sample.a = VectorXd::Zero(n);
  VectorXd f;
  for (const double t : times) {
    p.t = t;
    message.clear();
    const int flag = KINSol(mem, u.get(), KIN_LINESEARCH, u_scale.get(), f_scale.get());
    long iterations = 0;
    KINGetNumNonlinSolvIters(mem, &iterations);
    counters->newton_iterations += iterations;
    ++counters->position_solves;
    x = u_values;
    // KINSOL may stop on a tiny step short of the tolerance; judge the
    // residual here, in the same scaled norm.
    const bool converged = flag >= 0 && Evaluate(&p, x, &f) == 0 &&
                           MaxAbs(f.head(n)) <= options.tolerance * force_scale * 10.0 &&
                           (m == 0 || MaxAbs(f.tail(m)) <= options.tolerance * 10.0);
    if (!converged) {
      counters->residual_evaluations += p.evaluations;
      if (!system.FailureReason().empty()) return Failed(spec::FailureKind::kModelValidity, system.FailureReason());
      const std::string why = !p.callback_failure.empty() ? p.callback_failure
                              : !message.empty()          ? message
                                                          : absl::StrFormat("KINSOL flag %d", flag);
      return Failed(spec::FailureKind::kAssembly,
                    absl::StrFormat("no static equilibrium found at t = %.6g s (%s)", t, why));
    }
    bool stiffness_ok = true;
    const double least = RelativeLeastStiffness(&p, x, &stiffness_ok);
    if (!stiffness_ok) {
      counters->residual_evaluations += p.evaluations;
      return Failed(spec::FailureKind::kNonFiniteValue,
                    absl::StrFormat("the stiffness at the equilibrium at t = %.6g s is not finite", t));
    }
    if (least < -options.stability_tolerance) {
      counters->residual_evaluations += p.evaluations;
      return Failed(spec::FailureKind::kModelValidity,
                    absl::StrFormat("the static equilibrium at t = %.6g s is unstable (reduced stiffness "
                                    "eigenvalue %.3g of the largest): the mechanism would move away from it",
                                    t, least));
    }
    sample.t_s = t;
    sample.q = x.head(n);
    sample.lambda = x.tail(m);
    const spec::AnalysisFailure seen = at_instant(sample);
    if (!seen.ok()) {
      counters->residual_evaluations += p.evaluations;
      return seen;
    }
  }
  counters->residual_evaluations += p.evaluations;
  return spec::AnalysisFailure::Ok();
}

}  // namespace mbopt::multibody
