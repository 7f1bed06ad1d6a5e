#include "worker/multibody/explicit_dynamics.h"

#include <arkode/arkode_erkstep.h>
#include <nvector/nvector_serial.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "worker/multibody/integrator_setup.h"
#include "worker/sundials/sundials_handles.h"

namespace mbopt::multibody {
namespace {

using Eigen::Map;
using Eigen::MatrixXd;
using Eigen::VectorXd;

spec::AnalysisFailure Failed(spec::FailureKind kind, std::string reason) {
  return spec::AnalysisFailure::Of(kind, std::move(reason));
}

// The augmented system [M G^T; G 0][a; lambda] = [Q; gamma] by its Schur
// complement: with M^-1 (diagonal in absolute coordinates with each body's
// reference at its centre of mass, else Cholesky), (G M^-1 G^T) lambda =
// G M^-1 Q - gamma and a = M^-1 (Q - G^T lambda). The Schur complement is
// positive definite while the constraint rows are independent; a
// dependent set (a locked position) fails its Cholesky factorization.
// A system whose mass matrix is block diagonal (mass_block_size(): a
// spatial body's 7 coordinates) has each block factored alone and the
// Schur complement summed block by block over the few rows touching it.
struct Accelerations {
  MatrixXd mass, phi_q, mass_inv_phi_q_t, schur;
  VectorXd forces, gamma, mass_inv_forces;
  Eigen::LLT<MatrixXd> mass_llt, schur_llt;
  std::vector<Eigen::LLT<MatrixXd>> block_llts;
  std::vector<int> touching;

  // M^-1 Q, and with constraints M^-1 Phi_q^T and Phi_q M^-1 Phi_q^T,
  // through M's diagonal when it is diagonal, else its Cholesky factor.
  int DenseSolve(int m) {
    const bool diagonal = (mass.array() != 0.0).count() == (mass.diagonal().array() != 0.0).count();
    VectorXd inverse_diagonal;
    if (diagonal) {
      if (!(mass.diagonal().array() > 0.0).all()) return 1;
      inverse_diagonal = mass.diagonal().cwiseInverse();
      mass_inv_forces = inverse_diagonal.cwiseProduct(forces);
    } else {
      mass_llt.compute(mass);
      if (mass_llt.info() != Eigen::Success) return 1;
      mass_inv_forces = mass_llt.solve(forces);
    }
    if (m == 0) return 0;
    mass_inv_phi_q_t = diagonal ? MatrixXd(inverse_diagonal.asDiagonal() * phi_q.transpose())
                                : MatrixXd(mass_llt.solve(phi_q.transpose()));
    schur.noalias() = phi_q * mass_inv_phi_q_t;
    return 0;
  }

  // M^-1 Q, M^-1 Phi_q^T and Phi_q M^-1 Phi_q^T with blocks of size b.
  int SolveBlocks(int b, int n, int m) {
    const int blocks = n / b;
    block_llts.resize(static_cast<size_t>(blocks));
    mass_inv_forces.resize(n);
    mass_inv_phi_q_t.setZero(n, m);
    schur.setZero(m, m);
    for (int k = 0; k < blocks; ++k) {
      Eigen::LLT<MatrixXd>& llt = block_llts[static_cast<size_t>(k)];
      llt.compute(mass.block(k * b, k * b, b, b));
      if (llt.info() != Eigen::Success) return 1;
      mass_inv_forces.segment(k * b, b) = llt.solve(forces.segment(k * b, b));
      touching.clear();
      for (int r = 0; r < m; ++r) {
        if ((phi_q.row(r).segment(k * b, b).array() != 0.0).any()) touching.push_back(r);
      }
      if (touching.empty()) continue;
      const MatrixXd rows = phi_q(touching, Eigen::seqN(k * b, b));
      const MatrixXd solved = llt.solve(rows.transpose());
      mass_inv_phi_q_t(Eigen::seqN(k * b, b), touching) = solved;
      schur(touching, touching) += rows * solved;
    }
    return 0;
  }

  int Solve(const ConstrainedSystem& s, double t, const VectorXd& q, const VectorXd& v, VectorXd* a,
            VectorXd* lambda) {
    const int n = s.num_coordinates(), m = s.num_constraints();
    int flag = s.MassMatrix(q, &mass);
    if (flag == 0) flag = s.AppliedForces(t, q, v, &forces);
    if (flag == 0 && m > 0) flag = s.ConstraintJacobian(t, q, &phi_q);
    if (flag == 0 && m > 0) flag = s.AccelerationRightSide(t, q, v, &gamma);
    if (flag != 0) return flag;
    if (const int b = s.mass_block_size(); b > 0 && n % b == 0) {
      if (SolveBlocks(b, n, m) != 0) return 1;
    } else if (DenseSolve(m) != 0) {
      return 1;
    }
    if (m == 0) {
      *a = mass_inv_forces;
      lambda->resize(0);
      return a->allFinite() ? 0 : 1;
    }
    schur_llt.compute(schur);
    if (schur_llt.info() != Eigen::Success) return 1;
    *lambda = schur_llt.solve(phi_q * mass_inv_forces - gamma);
    a->resize(n);
    a->noalias() = mass_inv_forces - mass_inv_phi_q_t * *lambda;
    return a->allFinite() && lambda->allFinite() ? 0 : 1;
  }
};

// What the right-hand side and the projection need; lives for one
// integration.
struct Problem {
  const ConstrainedSystem* system = nullptr;
  int n = 0, m = 0;
  const budget::AnalysisBudget* budget = nullptr;
  spec::AnalysisFailure budget_failure;
  std::string callback_failure;
  Accelerations accelerations;
  VectorXd q, v, a, lambda;
  long rhs_evaluations = 0;
};

bool BudgetStops(Problem* p, double t) {
  if (p->budget == nullptr || !p->budget->Exhausted()) return false;
  p->budget_failure = p->budget->Check(t);
  return !p->budget_failure.ok();
}

int RightSide(realtype t, N_Vector yy, N_Vector yp, void* user_data) {
  auto* p = static_cast<Problem*>(user_data);
  return sundials::GuardCallback(&p->callback_failure, "the right-hand side", [&]() -> int {
    if (BudgetStops(p, t)) return -1;
    ++p->rhs_evaluations;
    const int n = p->n;
    const Map<const VectorXd> y(N_VGetArrayPointer(yy), 2 * n);
    Map<VectorXd> y_dot(N_VGetArrayPointer(yp), 2 * n);
    p->q = y.head(n);
    p->v = y.tail(n);
    // Trial stages past a validity bound stay finite; the bound's root
    // function ends the integration where the motion crosses it.
    const ContinuedPastBounds continued(*p->system);
    if (int flag = p->accelerations.Solve(*p->system, t, p->q, p->v, &p->a, &p->lambda); flag != 0) return flag;
    y_dot.head(n) = p->v;
    y_dot.tail(n) = p->a;
    return 0;
  });
}

int ValidityBounds(realtype t, N_Vector yy, realtype* g, void* user_data) {
  auto* p = static_cast<Problem*>(user_data);
  return sundials::GuardCallback(&p->callback_failure, "the validity bounds", [&]() -> int {
    const Map<const VectorXd> y(N_VGetArrayPointer(yy), 2 * p->n);
    p->system->ValidityBounds(t, y.head(p->n), y.tail(p->n), g);
    return 0;
  });
}

// Gauss-Newton iterations of the position projection: each squares the
// violation (times the constraints' curvature), so from a step's truncation
// error one or two reach the tolerance; more mean the step left the
// constraint manifold's neighbourhood.
constexpr int kMaxProjectionIterations = 6;
// The position projection's tolerance on |Phi| over the absolute tolerance:
// well below the error the integrator admits per step, so that the
// projection adds nothing visible to it.
constexpr double kProjectionFraction = 1e-2;

// Moves (q, v) onto Phi(t, q) = 0 and Phi_q v + Phi_t = 0 by minimum-norm
// corrections: dq = -G^T (G G^T)^-1 Phi repeated (Gauss-Newton), then
// dv = -G^T (G G^T)^-1 (G v + Phi_t) at the projected q (exact: it is
// linear in v). Returns false, with `why`, when the positions do not
// converge or G G^T is singular.
bool Project(const ConstrainedSystem& s, double t, double position_tolerance, Eigen::Ref<VectorXd> q,
             Eigen::Ref<VectorXd> v, std::string* why) {
  if (s.num_constraints() == 0) return true;
  VectorXd phi, phi_t;
  MatrixXd phi_q;
  Eigen::LLT<MatrixXd> normal;
  const ContinuedPastBounds continued(s);
  double previous_violation = std::numeric_limits<double>::infinity(), last_correction = 0.0;
  for (int iteration = 0;; ++iteration) {
    VectorXd q_copy = q;
    if (s.Constraints(t, q_copy, &phi) != 0 || !phi.allFinite()) {
      *why = absl::StrFormat("the constraints are not finite at t = %.6g s", t);
      return false;
    }
    const double violation = MaxAbs(phi);
    if (violation <= position_tolerance) break;
    // Rows written with a large scale (a spatial body's Euler-parameter
    // norm row, s (p.p - 1) with s = 1e6) have a rounding floor above the
    // tolerance: once a correction no longer halves |Phi| and moved q by
    // less than the tolerance, q is as close as the rows can tell.
    if (iteration > 0 && violation > 0.5 * previous_violation && last_correction <= position_tolerance) break;
    previous_violation = violation;
    if (iteration == kMaxProjectionIterations) {
      *why = absl::StrFormat(
          "the projection onto the constraints did not converge at t = %.6g s (|Phi| = %.3g after %d iterations)",
          t, violation, iteration);
      return false;
    }
    if (s.ConstraintJacobian(t, q_copy, &phi_q) != 0) {
      *why = absl::StrFormat("the constraint Jacobian is not finite at t = %.6g s", t);
      return false;
    }
    normal.compute(phi_q * phi_q.transpose());
    if (normal.info() != Eigen::Success) {
      *why = absl::StrFormat("dependent constraint rows at t = %.6g s: a locked position or redundant joints", t);
      return false;
    }
    const VectorXd correction = phi_q.transpose() * normal.solve(phi);
    q -= correction;
    last_correction = MaxAbs(correction);
  }
  const VectorXd q_copy = q;
  if (s.ConstraintJacobian(t, q_copy, &phi_q) != 0 || s.ConstraintTimeDerivative(t, q_copy, &phi_t) != 0) {
    *why = absl::StrFormat("the constraint Jacobian is not finite at t = %.6g s", t);
    return false;
  }
  normal.compute(phi_q * phi_q.transpose());
  if (normal.info() != Eigen::Success) {
    *why = absl::StrFormat("dependent constraint rows at t = %.6g s: a locked position or redundant joints", t);
    return false;
  }
  v -= phi_q.transpose() * normal.solve(phi_q * v + phi_t);
  return true;
}

ARKODE_ERKTableID TableOf(ForwardDynamicsOptions::ExplicitPair pair) {
  switch (pair) {
    case ForwardDynamicsOptions::ExplicitPair::kDormandPrince54:
      return ARKODE_DORMAND_PRINCE_7_4_5;
    case ForwardDynamicsOptions::ExplicitPair::kVerner65:
      return ARKODE_VERNER_8_5_6;
    case ForwardDynamicsOptions::ExplicitPair::kFehlberg87:
      return ARKODE_FEHLBERG_13_7_8;
  }
  return ARKODE_VERNER_8_5_6;
}

}  // namespace

spec::AnalysisFailure IntegrateForwardExplicit(const ConstrainedSystem& system, double t0, const VectorXd& q0,
                                               const VectorXd& v0, const std::vector<double>& times,
                                               const ForwardDynamicsOptions& options,
                                               const MotionCallback& at_instant, ForwardDynamicsCounters* counters) {
  Problem p;
  p.system = &system;
  p.n = system.num_coordinates();
  p.m = system.num_constraints();
  p.budget = options.budget;
  const int n = p.n, m = p.m;
  if (q0.size() != n || v0.size() != n) {
    return Failed(spec::FailureKind::kInvalidModel, "initial coordinates of the wrong size");
  }
  auto equations_failed = [&](double t) {
    if (!system.FailureReason().empty()) return Failed(spec::FailureKind::kModelValidity, system.FailureReason());
    return Failed(spec::FailureKind::kNonFiniteValue,
                  absl::StrFormat("the equations are not finite or the constraint rows are dependent at t = %.6g s "
                                  "(a locked position or redundant joints)",
                                  t));
  };
  // The start's accelerations: also the test that the augmented system is
  // regular there.
  if (p.accelerations.Solve(system, t0, q0, v0, &p.a, &p.lambda) != 0) return equations_failed(t0);

  SundialsCalls check;
  struct Handles {
    sundials::Context context;
    sundials::Vector y, interpolated;
    sundials::Memory<&ERKStepFree> erk;
  } h;
  if (spec::AnalysisFailure f = CreateContextAndVectors(2 * n, &h.context, {&h.y, &h.interpolated}); !f.ok()) return f;
  Map<VectorXd> y(N_VGetArrayPointer(h.y.get()), 2 * n);
  y.head(n) = q0;
  y.tail(n) = v0;
  h.erk.reset(ERKStepCreate(&RightSide, t0, h.y.get(), h.context.get()));
  if (!h.erk) return Failed(spec::FailureKind::kIntegrator, "ERKStepCreate failed");
  void* erk = h.erk.get();
  // The outputs and the validity bounds' root finding read the interpolant
  // over one step (the restart after every projection clears it): Hermite's
  // of degree 5 from the step's ends and derivatives (one right-hand side
  // at every step's end, two more per output). When every step stops at
  // the next instant and there are no bounds nothing reads it, and
  // Lagrange's, which costs no right-hand side, saves those (11 % of the
  // evaluations on the rod chain, the same steps and results).
  const bool reads_interpolant = !options.explicit_stop_at_instants || system.num_validity_bounds() > 0;
  bool ok = check(ERKStepSetErrHandlerFn(erk, &sundials::CaptureMessage, check.message_sink()),
                  "ERKStepSetErrHandlerFn") &&
            check(ERKStepSetUserData(erk, &p), "ERKStepSetUserData") &&
            check(ERKStepSetTableNum(erk, TableOf(options.explicit_pair)), "ERKStepSetTableNum") &&
            (reads_interpolant
                 ? check(ERKStepSetInterpolantDegree(erk, ARK_INTERP_MAX_DEGREE), "ERKStepSetInterpolantDegree")
                 : check(ERKStepSetInterpolantType(erk, ARK_INTERP_LAGRANGE), "ERKStepSetInterpolantType")) &&
            check(ERKStepSStolerances(erk, options.relative_tolerance, options.absolute_tolerance),
                  "ERKStepSStolerances") &&
            check(ERKStepSetMaxNumSteps(erk, options.max_steps), "ERKStepSetMaxNumSteps") &&
            (options.max_step_size <= 0.0 || check(ERKStepSetMaxStep(erk, options.max_step_size), "ERKStepSetMaxStep"));
  if (!ok) return check.Failure();

  const int num_bounds = system.num_validity_bounds();
  std::vector<int> bounds_crossed(static_cast<size_t>(num_bounds), 0);
  std::vector<int> downwards(static_cast<size_t>(num_bounds), -1);
  auto init_roots = [&]() {
    return num_bounds == 0 || (check(ERKStepRootInit(erk, num_bounds, &ValidityBounds), "ERKStepRootInit") &&
                               check(ERKStepSetRootDirection(erk, downwards.data()), "ERKStepSetRootDirection") &&
                               check(ERKStepSetNoInactiveRootWarn(erk), "ERKStepSetNoInactiveRootWarn"));
  };
  if (num_bounds > 0) {
    if (spec::AnalysisFailure f = ValidityBoundsHoldAtStart(system, t0, q0, v0); !f.ok()) return f;
    if (!init_roots()) return check.Failure();
  }

  // The projection's tolerance: a fraction of the absolute tolerance, but
  // not below what the coordinates' round-off lets Phi reach.
  const double position_tolerance =
      std::max(kProjectionFraction * options.absolute_tolerance,
               64.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, MaxAbs(q0)));
  const double defined_until = system.DefinedUntil_s();

  // One step at a time; after each, the step's state is projected and the
  // integrator restarts from it (ERKStepReset) with the step it had chosen.
  // The restart drops the error controller's history, and the pair
  // recomputes its first stage at the new state anyway. By default
  // (explicit_stop_at_instants) every step ends at most at the next output
  // instant, so an output is a step's state; otherwise the outputs inside a
  // step come from ERKStep's interpolant over it, each projected like the
  // steps (the step's own state left as it is).
  std::string why;
  double t_reached = t0;
  long steps = 0, error_test_failures = 0, last_error_test_failures = 0;
  VectorXd phi, phi_t;
  MatrixXd phi_q;
  Map<VectorXd> y_out(N_VGetArrayPointer(h.interpolated.get()), 2 * n);
  auto failed_near = [&](double t, double target, int flag) {
    if (!system.FailureReason().empty()) {
      return Failed(spec::FailureKind::kModelValidity,
                    absl::StrFormat("%s; the integrator gave up near t = %.6g s", system.FailureReason(), t));
    }
    if (!p.budget_failure.ok()) return p.budget_failure;
    const std::string callback = p.callback_failure.empty() ? "" : " [" + p.callback_failure + "]";
    std::string advice;
    if (flag == ARK_TOO_MUCH_WORK) {
      advice = absl::StrFormat(
          "; an explicit method's step is bounded by its stability: a stiff model (stiff springs, flexible links, "
          "fast dampers) needs integrator IDAS (the default), or a larger max_steps (now %d)",
          static_cast<int>(options.max_steps));
    }
    return Failed(spec::FailureKind::kIntegrator,
                  absl::StrFormat("the explicit Runge-Kutta integrator failed near t = %.6g s (target %.6g s): %s%s%s",
                                  t, target, check.message(), callback, advice));
  };
  // The state at t (consistent with the constraints) to the caller.
  auto emit = [&](double t, const VectorXd& q, const VectorXd& v) {
    MotionSample sample;
    sample.t_s = t;
    sample.q = q;
    sample.v = v;
    if (p.accelerations.Solve(system, t, sample.q, sample.v, &sample.a, &sample.lambda) != 0) {
      return equations_failed(t);
    }
    if (m > 0) {
      system.Constraints(t, sample.q, &phi);
      system.ConstraintJacobian(t, sample.q, &phi_q);
      system.ConstraintTimeDerivative(t, sample.q, &phi_t);
      counters->max_position_drift = std::max(counters->max_position_drift, MaxAbs(phi));
      counters->max_velocity_drift = std::max(counters->max_velocity_drift, MaxAbs(phi_q * sample.v + phi_t));
    }
    counters->steps = steps;
    counters->residual_evaluations = p.rhs_evaluations;
    counters->error_test_failures = error_test_failures;
    return at_instant(sample);
  };
  size_t next = 0;
  for (; next < times.size() && times[next] <= t0; ++next) {
    if (spec::AnalysisFailure f = emit(times[next], y.head(n), y.tail(n)); !f.ok()) return f;
  }
  const double end = times.empty() ? t0 : std::min(times.back(), defined_until);
  while (next < times.size()) {
    if (t_reached >= end) {
      return Failed(spec::FailureKind::kModelValidity,
                    absl::StrFormat("a tabulated profile ends at t = %.6g s, before the instant t = %.6g s", t_reached,
                                    times[next]));
    }
    const double stop = options.explicit_stop_at_instants ? std::min(times[next], end) : end;
    if (!check(ERKStepSetStopTime(erk, stop), "ERKStepSetStopTime")) {
      return check.Failure();
    }
    if (steps >= options.max_steps) return failed_near(t_reached, times[next], ARK_TOO_MUCH_WORK);
    realtype t_step = t_reached;
    const int flag = ERKStepEvolve(erk, stop, h.y.get(), &t_step, ARK_ONE_STEP);
    long value = 0;
    if (ERKStepGetNumErrTestFails(erk, &value) == ARK_SUCCESS) {
      error_test_failures += value >= last_error_test_failures ? value - last_error_test_failures : value;
      last_error_test_failures = value;
    }
    if (flag < 0) return failed_near(t_reached, times[next], flag);
    ++steps;
    if (flag == ARK_ROOT_RETURN) {
      if (!check(ERKStepGetRootInfo(erk, bounds_crossed.data()), "ERKStepGetRootInfo")) {
        return check.Failure();
      }
      const int k = static_cast<int>(std::find(bounds_crossed.begin(), bounds_crossed.end(), -1) -
                                     bounds_crossed.begin());
      const VectorXd q = y.head(n), v = y.tail(n);
      return Failed(spec::FailureKind::kModelValidity, system.BoundReason(k < num_bounds ? k : 0, t_step, q, v));
    }
    for (; next < times.size() && times[next] <= t_step; ++next) {
      if (times[next] == t_step) {
        y_out = y;
      } else if (!check(ERKStepGetDky(erk, times[next], 0, h.interpolated.get()), "ERKStepGetDky")) {
        return check.Failure();
      }
      if (!Project(system, times[next], position_tolerance, y_out.head(n), y_out.tail(n), &why)) {
        return Failed(spec::FailureKind::kIntegrator, why);
      }
      if (spec::AnalysisFailure f = emit(times[next], y_out.head(n), y_out.tail(n)); !f.ok()) return f;
    }
    t_reached = t_step;
    if (!Project(system, t_reached, position_tolerance, y.head(n), y.tail(n), &why)) {
      return Failed(spec::FailureKind::kIntegrator, why);
    }
    realtype next_step = 0.0;
    if (!check(ERKStepGetCurrentStep(erk, &next_step), "ERKStepGetCurrentStep") ||
        (next_step > 0.0 && !check(ERKStepSetInitStep(erk, next_step), "ERKStepSetInitStep")) ||
        !check(ERKStepReset(erk, t_reached, h.y.get()), "ERKStepReset") || !init_roots()) {
      return check.Failure();
    }
  }
  counters->steps = steps;
  counters->residual_evaluations = p.rhs_evaluations;
  counters->error_test_failures = error_test_failures;
  return spec::AnalysisFailure::Ok();
}

}  // namespace mbopt::multibody
