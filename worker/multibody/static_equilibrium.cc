#include "worker/multibody/static_equilibrium.h"

#include <kinsol/kinsol.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "absl/strings/str_format.h"
#include "worker/multibody/parameter_derivatives.h"
#include "worker/sundials/sundials_handles.h"

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
  VectorXd offset;  // the homotopy's (1 - s) F(start), subtracted from F; empty otherwise
  MatrixXd newton;  // NewtonMatrix's and Stiffness's
  // The system's derivatives are its exact state Jacobian and the options
  // ask for them: KINSOL's Newton matrix and the stiffness are analytic.
  bool analytic = false;
  std::int64_t newton_matrices = 0;
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
  if (p->offset.size() == n + m) *f -= p->offset;
  return f->allFinite() ? 0 : 1;
}

int Residual(N_Vector uu, N_Vector ff, void* user_data) {
  auto* p = static_cast<Problem*>(user_data);
  return sundials::GuardCallback(&p->callback_failure, "the residual", [&]() -> int {
    const int size = p->n + p->m;
    const VectorXd x = Map<const VectorXd>(N_VGetArrayPointer(uu), size);
    VectorXd f;
    const int flag = Evaluate(p, x, &f);
    if (flag != 0) return flag;
    Map<VectorXd>(N_VGetArrayPointer(ff), size) = f;
    return 0;
  });
}

spec::AnalysisFailure Failed(spec::FailureKind kind, std::string reason) {
  return spec::AnalysisFailure::Of(kind, std::move(reason));
}

bool EquilibriumJacobianAt(const Problem& p, const VectorXd& x, MatrixXd* jacobian);

// dF/dq of the force rows (the stiffness): the analytic matrix's block where
// the system's derivatives are exact (the matrix KINSOL's Newton steps
// use), else central differences of the residual.
bool Stiffness(Problem* p, const VectorXd& x, MatrixXd* k) {
  const int n = p->n;
  if (p->analytic) {
    if (!EquilibriumJacobianAt(*p, x, &p->newton)) return false;
    *k = p->newton.topLeftCorner(n, n);
    return k->allFinite();
  }
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
    // Rows of unit length for the rank decision: the QR's threshold is
    // relative to its largest pivot, and a spatial body's norm row (2e6 p^T)
    // would otherwise hide a joint row of unit size. The null space is the
    // same, so are the reduced eigenvalues (N is orthonormal either way).
    MatrixXd rows = p->phi_q;
    for (int i = 0; i < rows.rows(); ++i) {
      const double norm = rows.row(i).norm();
      if (norm > 0.0) rows.row(i) /= norm;
    }
    Eigen::ColPivHouseholderQR<MatrixXd> qr(rows.transpose());
    qr.setThreshold(1e-9);
    qr.compute(rows.transpose());
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

// KINSOL's Newton matrix, analytic (EquilibriumJacobian) instead of
// KINSOL's n + m residuals a matrix by difference quotients.
int NewtonMatrix(N_Vector uu, N_Vector /*fu*/, SUNMatrix matrix, void* user_data, N_Vector /*tmp1*/,
                 N_Vector /*tmp2*/) {
  auto* p = static_cast<Problem*>(user_data);
  return sundials::GuardCallback(&p->callback_failure, "the Newton matrix", [&]() -> int {
    const int n = p->n, m = p->m, size = n + m;
    const Map<const VectorXd> x(N_VGetArrayPointer(uu), size);
    if (!EquilibriumJacobianAt(*p, x, &p->newton)) return 1;
    if (!p->newton.allFinite()) return 1;
    ++p->newton_matrices;
    Map<MatrixXd>(SUNDenseMatrix_Data(matrix), size, size) = p->newton;
    return 0;
  });
}

bool EquilibriumJacobianAt(const Problem& p, const VectorXd& x, MatrixXd* jacobian) {
  return EquilibriumJacobian(*p.system, p.t, x.head(p.n), x.tail(p.m), jacobian);
}

}  // namespace

bool EquilibriumJacobian(const ConstrainedSystem& system, double t, const VectorXd& q, const VectorXd& lambda,
                         MatrixXd* jacobian) {
  if (!system.has_exact_state_jacobian()) return false;
  const int n = system.num_coordinates(), m = system.num_constraints();
  MatrixXd force_q, force_v, phi_q, curvature;
  if (system.ForceJacobians(t, q, VectorXd::Zero(n), &force_q, &force_v) != 0) return false;
  jacobian->setZero(n + m, n + m);
  jacobian->topLeftCorner(n, n) = force_q;
  if (m > 0) {
    if (system.ConstraintJacobian(t, q, &phi_q) != 0 || system.ConstraintCurvature(t, q, lambda, &curvature) != 0) {
      return false;
    }
    jacobian->topLeftCorner(n, n) -= curvature;
    jacobian->topRightCorner(n, m) = -phi_q.transpose();
    jacobian->bottomLeftCorner(m, n) = phi_q;
  }
  return true;
}

bool StaticStateSensitivities(const ConstrainedSystem& system, const std::vector<ParameterPerturbation>& parameters,
                              const MotionSample& sample, std::vector<StateSensitivity>* sensitivities) {
  if (!system.has_exact_state_jacobian()) return false;
  const int n = system.num_coordinates(), m = system.num_constraints();
  const double t = sample.t_s;
  const VectorXd& q = sample.q;
  const VectorXd lambda = m > 0 ? sample.lambda : VectorXd();
  MatrixXd jacobian;
  if (!EquilibriumJacobian(system, t, q, lambda, &jacobian)) return false;
  const Eigen::FullPivLU<MatrixXd> lu(jacobian);
  if (!lu.isInvertible()) return false;
  sensitivities->resize(parameters.size());
  VectorXd partial;
  for (size_t k = 0; k < parameters.size(); ++k) {
    if (StaticParameterDerivative(parameters[k], t, q, lambda, &partial) != 0) return false;
    const VectorXd dx = -lu.solve(partial);
    if (!dx.allFinite()) return false;
    StateSensitivity& out = (*sensitivities)[k];
    out.q = dx.head(n);
    out.v = VectorXd::Zero(n);
    out.a = VectorXd::Zero(n);
    out.lambda = dx.tail(m);
  }
  return true;
}

spec::AnalysisFailure RunStaticEquilibrium(const ConstrainedSystem& system, const VectorXd& q0,
                                           const std::vector<double>& times, const StaticOptions& options,
                                           const MotionCallback& at_instant, StaticCounters* counters) {
  Problem p;
  p.system = &system;
  p.n = system.num_coordinates();
  p.m = system.num_constraints();
  const int n = p.n, m = p.m, size = n + m;
  if (q0.size() != n) return Failed(spec::FailureKind::kInvalidModel, "initial coordinates of the wrong size");
  if (times.empty()) return spec::AnalysisFailure::Ok();
  p.zero_velocity = VectorXd::Zero(n);
  p.t = times.front();
  // The analytic matrix where the system's derivatives are its exact state
  // Jacobian; a spatial system's (which leaves out terms) would slow Newton
  // down to linear convergence, so its matrices are difference quotients.
  p.analytic = options.analytic_newton_matrix && system.has_exact_state_jacobian();

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
  // Each force row is converged at tolerance * force_scale, or at its own
  // round-off floor if that is higher: a stiff element (a beam's EA / L of
  // 1e9 N/m) makes its rows' residual noisy at eps * K_ii * |q|, far above
  // 1e-10 N, where Newton can make no further progress.
  VectorXd row_tolerance = VectorXd::Constant(n, options.tolerance * force_scale);
  VectorXd constraint_tolerance = VectorXd::Constant(m, options.tolerance);
  const double floor = 100.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, MaxAbs(q0));
  {
    MatrixXd dfdq;
    if (Stiffness(&p, x, &dfdq)) {
      // A body's translation rows share one floor: as an element turns, its
      // axial stiffness moves between them; so do its rotation rows.
      const int per_body = options.coordinates_per_body, translations = options.translations_per_body;
      for (int i = 0; i + per_body - 1 < n; i += per_body) {
        double translation = 0.0, rotation = 0.0;
        for (int k = 0; k < translations; ++k) translation = std::max(translation, std::abs(dfdq(i + k, i + k)));
        for (int k = translations; k < per_body; ++k) rotation = std::max(rotation, std::abs(dfdq(i + k, i + k)));
        for (int k = 0; k < per_body; ++k) {
          row_tolerance[i + k] = std::max(row_tolerance[i + k], floor * (k < translations ? translation : rotation));
        }
      }
    }
  }
  if (m > 0) {
    for (int j = 0; j < m; ++j) {
      constraint_tolerance[j] = std::max(constraint_tolerance[j], floor * p.phi_q.row(j).cwiseAbs().maxCoeff());
    }
  }

  sundials::Context context = sundials::MakeContext();
  if (!context) return Failed(spec::FailureKind::kIntegrator, "KINSOL: no SUNDIALS context");
  sundials::Vector u(N_VNew_Serial(size, context.get()));
  sundials::Vector u_scale(N_VNew_Serial(size, context.get()));
  sundials::Vector f_scale(N_VNew_Serial(size, context.get()));
  sundials::Matrix jacobian(SUNDenseMatrix(size, size, context.get()));
  if (!u || !u_scale || !f_scale || !jacobian) return Failed(spec::FailureKind::kIntegrator, "KINSOL: out of memory");
  sundials::LinearSolver solver(SUNLinSol_Dense(u.get(), jacobian.get(), context.get()));
  sundials::Memory<KINFree> kinsol(KINCreate(context.get()));
  if (!solver || !kinsol) return Failed(spec::FailureKind::kIntegrator, "KINSOL: out of memory");
  std::string message;
  N_VConst(1.0, u_scale.get());
  Map<VectorXd> fs(N_VGetArrayPointer(f_scale.get()), size);
  fs.head(n) = options.tolerance * row_tolerance.cwiseInverse();
  for (int j = 0; j < m; ++j) {
    // Exactly 1 where the floor is below the tolerance (planar rows), as before.
    fs[n + j] = constraint_tolerance[j] > options.tolerance ? options.tolerance / constraint_tolerance[j] : 1.0;
  }
  void* mem = kinsol.get();
  if (KINInit(mem, Residual, u.get()) != KIN_SUCCESS || KINSetUserData(mem, &p) != KIN_SUCCESS ||
      KINSetErrHandlerFn(mem, sundials::CaptureMessage, &message) != KIN_SUCCESS ||
      KINSetLinearSolver(mem, solver.get(), jacobian.get()) != KIN_SUCCESS ||
      (p.analytic && KINSetJacFn(mem, NewtonMatrix) != KIN_SUCCESS) ||
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
  // One KINSOL solve from u_values; KINSOL may stop on a tiny step short
  // of the tolerance, so the residual is judged here, row by row.
  int flag = 0;
  auto solve = [&](int strategy) {
    message.clear();
    flag = KINSol(mem, u.get(), strategy, u_scale.get(), f_scale.get());
    long iterations = 0;
    KINGetNumNonlinSolvIters(mem, &iterations);
    counters->newton_iterations += iterations;
    // (Evaluate subtracts the homotopy's offset, if any.)
    // A line search that cannot move at the round-off floor is judged by
    // the residual like a converged solve.
    return (flag >= 0 || flag == KIN_LINESEARCH_NONCONV) && Evaluate(&p, u_values, &f) == 0 &&
           (f.head(n).cwiseAbs().array() <= 10.0 * row_tolerance.array()).all() &&
           (f.tail(m).cwiseAbs().array() <= 10.0 * constraint_tolerance.array()).all();
  };
  auto charge = [&](double t) {
    return options.budget != nullptr ? options.budget->ChargeSteps(1, t) : spec::AnalysisFailure::Ok();
  };
  for (const double t : times) {
    p.t = t;
    if (spec::AnalysisFailure f = charge(t); !f.ok()) {
      counters->residual_evaluations += p.evaluations;
      counters->newton_matrices += p.newton_matrices;
      return f;
    }
    ++counters->position_solves;
    const VectorXd start = u_values;
    bool converged = solve(KIN_LINESEARCH);
    if (!converged) {
      // Newton homotopy from the start: F(x) = (1 - s) F(start), s from 0
      // to 1 in adaptive steps. For loads that deform a flexible link far
      // (a cantilever bent by tens of degrees) this is load incrementation;
      // plain Newton from the undeformed shape overshoots.
      u_values = start;
      VectorXd f_start;
      if (Evaluate(&p, start, &f_start) == 0) {
        double s_done = 0.0, step = 0.25;
        while (s_done < 1.0 && step >= 1.0 / 4096) {
          if (spec::AnalysisFailure f = charge(t); !f.ok()) {
            counters->residual_evaluations += p.evaluations;
            counters->newton_matrices += p.newton_matrices;
            return f;
          }
          const double s_next = std::min(1.0, s_done + step);
          const VectorXd before = u_values;
          p.offset = (1.0 - s_next) * f_start;
          // Small steps from a solution: plain Newton.
          if (solve(KIN_NONE)) {
            s_done = s_next;
            step = std::min(0.5, 1.5 * step);
          } else {
            u_values = before;
            step /= 2;
          }
        }
        p.offset.resize(0);
        converged = s_done >= 1.0 && solve(KIN_NONE);
      }
    }
    x = u_values;
    if (!converged) {
      counters->residual_evaluations += p.evaluations;
      counters->newton_matrices += p.newton_matrices;
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
      counters->newton_matrices += p.newton_matrices;
      return Failed(spec::FailureKind::kNonFiniteValue,
                    absl::StrFormat("the stiffness at the equilibrium at t = %.6g s is not finite", t));
    }
    if (least < -options.stability_tolerance) {
      counters->residual_evaluations += p.evaluations;
      counters->newton_matrices += p.newton_matrices;
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
      counters->newton_matrices += p.newton_matrices;
      return seen;
    }
  }
  counters->residual_evaluations += p.evaluations;
  counters->newton_matrices += p.newton_matrices;
  return spec::AnalysisFailure::Ok();
}

}  // namespace mbopt::multibody
