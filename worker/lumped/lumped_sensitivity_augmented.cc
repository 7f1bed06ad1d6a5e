// States and sensitivities integrated by CVODES as one system (see
// lumped_sensitivity_problem.h).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <memory>

#include "absl/strings/str_cat.h"
#include "worker/sundials/cvodes_integrator.h"
#include "worker/sundials/integrate_across_kinks.h"
#include "worker/lumped/lumped_newton_operator.h"
#include "worker/lumped/lumped_sensitivity_problem.h"

namespace mbopt::lumped::sensitivity_internal {

spec::AnalysisFailure IntegrateAugmented(SensitivityProblem* p, const spec::IntegratorSettings& settings,
                               const LumpedSensitivityOptions& options, double omega_max,
                               const std::vector<double>& pbar,
                               const std::vector<double>& instants, const SensitivityRecorder& record,
                               spec::AnalysisCounters* counters,
                               LumpedSensitivityCounters* sensitivity_counters) {
  const LumpedModel& m = *p->model;
  const int n = p->n;
  const int ns = static_cast<int>(p->derivatives.size());
  const int block = 2 * n;
  const int size = block * (1 + ns);
  // B_k's only nonzero rows (the rate rows): M^-1 (dM M^-1 [K C] - [dK dC]).
  std::vector<Eigen::MatrixXd> coupling(static_cast<size_t>(ns));
  Eigen::MatrixXd minv_kc(n, 2 * n);
  minv_kc << p->minv_k, p->minv_c;
  for (int k = 0; k < ns; ++k) {
    const ParameterDerivative& d = p->derivatives[static_cast<size_t>(k)];
    Eigen::MatrixXd b = d.mass_diagonal.asDiagonal() * minv_kc;
    b.leftCols(n) -= d.stiffness;
    b.rightCols(n) -= d.damping;
    coupling[static_cast<size_t>(k)] = p->inverse_mass.asDiagonal() * b;
  }
  auto rhs = [p, n, ns, block](double t, const double* y, double* ydot) -> int {
    const Eigen::Map<const Eigen::VectorXd> q(y, n), v(y + n, n);
    Eigen::Map<Eigen::VectorXd> qdot(ydot, n), vdot(ydot + n, n);
    qdot = v;
    p->model->Forcing(t, &p->force);
    vdot = p->inverse_mass.cwiseProduct(p->force);
    vdot.noalias() -= p->minv_k * q;
    vdot.noalias() -= p->minv_c * v;
    if (!vdot.allFinite()) return -1;
    for (int k = 0; k < ns; ++k) {
      const double* in = y + block * (1 + k);
      double* out = ydot + block * (1 + k);
      const Eigen::Map<const Eigen::VectorXd> s(in, n), sv(in + n, n);
      Eigen::Map<Eigen::VectorXd> a(out + n, n);
      p->AccelerationDerivative(k, t, q, v, vdot, s, sv, a);
      Eigen::Map<Eigen::VectorXd>(out, n) = sv;
      if (!a.allFinite()) return -1;
    }
    return 0;
  };
  // Each block through the plain integration's operator; a sensitivity
  // block's right-hand side first takes the coupling to the state block
  // already solved (the Newton matrix is block lower triangular).
  LumpedNewtonOperator newton(m);
  Eigen::VectorXd state_x(block);
  auto newton_solve = [&](double, double gamma, double* bx, bool* refactored) -> int {
    if (newton.Prepare(gamma)) *refactored = true;
    for (int k = 0; k <= ns; ++k) {
      double* x = bx + block * k;
      Eigen::Map<Eigen::VectorXd> b(x, block), bv(x + n, n);
      if (k > 0) bv.noalias() += gamma * (coupling[static_cast<size_t>(k - 1)] * state_x);
      if (!newton.Solve(x)) return 1;
      if (k == 0) state_x = b;
    }
    return 0;
  };

  // CVODES' sensitivity module requires each of the 1 + ns blocks to pass
  // the error test on its own (the largest of the block norms); the
  // augmented system has one WRMS norm over all blocks, which averages a
  // large error in one block with small ones elsewhere. Dividing every
  // tolerance by sqrt(1 + ns) makes that norm the root-sum-square of the
  // block norms, never less than the largest: the test is at least as
  // strict as the module's.
  const double norm_bound = options.augmented_block_norm_bound ? std::sqrt(1.0 + ns) : 1.0;
  sundials::CvodesOptions cv;
  cv.relative_tolerance = settings.relative_tolerance / norm_bound;
  cv.max_steps = settings.max_steps;
  cv.budget = options.budget;
  cv.absolute_tolerances.resize(size);
  for (int k = 0; k <= ns; ++k) {
    const double scale = (k == 0 ? 1.0 : 1.0 / pbar[static_cast<size_t>(k - 1)]) / norm_bound;
    cv.absolute_tolerances.segment(block * k, n).setConstant(settings.absolute_tolerance * scale);
    cv.absolute_tolerances.segment(block * k + n, n)
        .setConstant(settings.absolute_tolerance * std::max(1.0, omega_max) * scale);
  }
  Eigen::VectorXd y = Eigen::VectorXd::Zero(size);
  absl::StatusOr<std::unique_ptr<sundials::CvodesIntegrator>> created =
      sundials::CvodesIntegrator::CreateWithNewtonSolver(size, rhs, newton_solve,
                                               sundials::CvodesIntegrator::NewtonRefresh::kCvodesSetups, cv,
                                               0.0, y);
  if (!created.ok()) {
    return spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator,
                                     absl::StrCat("integrator setup: ", created.status().message()));
  }
  sundials::CvodesIntegrator& integrator = **created;

  const double t_last = instants.empty() ? 0.0 : instants.back();
  const spec::AnalysisFailure failure = sundials::IntegrateAcrossKinks(
      integrator, m.KinkTimes(0.0, t_last), instants, &y, [&](double t, const Eigen::VectorXd& state) {
        record(t, state.head(block), [&](int k) { return state.data() + block * (1 + k); });
        return spec::AnalysisFailure::Ok();
      });
  const sundials::CvodesCounters c = integrator.counters();
  counters->time_steps = c.steps;
  counters->rhs_evaluations = c.rhs_evaluations;
  counters->jacobian_evaluations = c.jacobian_evaluations;
  counters->newton_iterations = c.nonlinear_iterations;
  // One right-hand side evaluates every sensitivity; one Newton iteration
  // corrects them all.
  sensitivity_counters->sensitivity_rhs_evaluations = c.rhs_evaluations;
  sensitivity_counters->sensitivity_newton_iterations = c.nonlinear_iterations;
  sensitivity_counters->linear_setups = c.jacobian_evaluations;
  sensitivity_counters->error_test_failures = c.error_test_failures;
  return failure;
}

}  // namespace mbopt::lumped::sensitivity_internal
