#include "worker/lumped/lumped_dynamics.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <variant>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "worker/sundials/cvodes_integrator.h"
#include "worker/sundials/integrate_across_kinks.h"
#include "worker/lumped/lumped_newton_operator.h"

namespace mbopt::lumped {
namespace {

spec::AnalysisReport Failed(spec::AnalysisReport report, spec::FailureKind kind, std::string reason) {
  report.Fail(kind, std::move(reason));  // partial series must not pass for results
  return report;
}
spec::AnalysisReport Failed(spec::AnalysisReport report, const spec::AnalysisFailure& failure) {
  return Failed(std::move(report), failure.kind, failure.reason);
}

// What to evaluate for one requested output at each instant.
struct OutputPlan {
  enum class Kind { kDeflection, kAcceleration, kDisplacement, kVelocity } kind = Kind::kDeflection;
  int element = -1;
  int body = -1;
  double offset_x_m = 0, offset_y_m = 0;
  spec::Axis axis = spec::Axis::kY;
};

}  // namespace

spec::AnalysisFailure IntegrateLumped(const LumpedModel& m, const std::vector<double>& instants_s,
                            const spec::IntegratorSettings& settings,
                            const LumpedDynamicsOptions& options,
                            const LumpedInstantCallback& at_instant,
                            spec::AnalysisCounters* counters) {
  const int n = m.num_coordinates();
  // y' = A y + (0, M^-1 f(t)) with A = [0 I; -M^-1 K  -M^-1 C].
  const Eigen::VectorXd inverse_mass = m.mass_diagonal().cwiseInverse();
  // M^-1 [K C] as one n x 2n block: a single product with y per call.
  Eigen::MatrixXd minv_kc(n, 2 * n);
  minv_kc << inverse_mass.asDiagonal() * m.stiffness(), inverse_mass.asDiagonal() * m.damping();
  Eigen::VectorXd force(n);
  auto rhs = [&](double t, const double* y, double* ydot) -> int {
    Eigen::Map<const Eigen::VectorXd> state(y, 2 * n), v(y + n, n);
    Eigen::Map<Eigen::VectorXd> qdot(ydot, n), vdot(ydot + n, n);
    qdot = v;
    m.Forcing(t, &force);
    vdot = inverse_mass.cwiseProduct(force);
    vdot.noalias() -= minv_kc * state;
    return 0;
  };
  LumpedNewtonOperator newton(m);
  auto newton_solve = [&](double, double gamma, double* bx, bool* refactored) -> int {
    if (newton.Prepare(gamma)) *refactored = true;
    return newton.Solve(bx) ? 0 : 1;
  };

  sundials::CvodesOptions cv;
  cv.method = options.adams ? sundials::CvodesOptions::Method::kAdams : sundials::CvodesOptions::Method::kBdf;
  if (options.adams && options.fixed_point) cv.iteration = sundials::CvodesOptions::Iteration::kFixedPoint;
  cv.relative_tolerance = settings.relative_tolerance;
  cv.absolute_tolerance = settings.absolute_tolerance;
  cv.max_steps = settings.max_steps;
  cv.budget = options.budget;
  // Rates are larger than coordinates by about the natural frequencies; a
  // common absolute tolerance would make the fastest mode's rates dominate
  // the error norm long after that mode has died out.
  const Eigen::VectorXd inverse_root_mass = inverse_mass.cwiseSqrt();
  const Eigen::MatrixXd normalized_stiffness =
      inverse_root_mass.asDiagonal() * m.stiffness() * inverse_root_mass.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> modes(normalized_stiffness,
                                                             Eigen::EigenvaluesOnly);
  const double omega_max = std::sqrt(std::max(0.0, modes.eigenvalues().maxCoeff()));
  cv.absolute_tolerances.resize(2 * n);
  cv.absolute_tolerances.head(n).setConstant(settings.absolute_tolerance);
  cv.absolute_tolerances.tail(n).setConstant(settings.absolute_tolerance *
                                             std::max(1.0, omega_max));
  Eigen::VectorXd y = Eigen::VectorXd::Zero(2 * n);
  if (options.initial_q.size() == n) y.head(n) = options.initial_q;
  if (options.initial_qdot.size() == n) y.tail(n) = options.initial_qdot;
  absl::StatusOr<std::unique_ptr<sundials::CvodesIntegrator>> created =
      cv.iteration == sundials::CvodesOptions::Iteration::kNewton
          ? sundials::CvodesIntegrator::CreateWithNewtonSolver(
                2 * n, rhs, newton_solve, sundials::CvodesIntegrator::NewtonRefresh::kCvodesSetups, cv, 0.0, y)
          : sundials::CvodesIntegrator::Create(2 * n, rhs, nullptr, cv, 0.0, y);
  if (!created.ok()) {
    return spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator,
                                     absl::StrCat("integrator setup: ", created.status().message()));
  }
  sundials::CvodesIntegrator& integrator = **created;

  const double t_last = instants_s.empty() ? 0.0 : instants_s.back();
  const spec::AnalysisFailure failure = sundials::IntegrateAcrossKinks(
      integrator, m.KinkTimes(0.0, t_last), instants_s, &y,
      [&](double t, const Eigen::VectorXd& state) { return at_instant(t, state.head(n), state.tail(n)); });
  const sundials::CvodesCounters c = integrator.counters();
  counters->time_steps = c.steps;
  counters->rhs_evaluations = c.rhs_evaluations;
  counters->jacobian_evaluations = c.jacobian_evaluations;
  counters->newton_iterations = c.nonlinear_iterations;
  return failure;
}

spec::AnalysisReport SimulateLumped(const spec::Scene& scene,
                                      const std::vector<double>& parameter_values_si,
                                      const LumpedDynamicsOptions& options) {
  spec::AnalysisReport report;
  report.formulation = spec::Formulation::kDynamic;
  report.times_s = scene.time_grid.Instants();
  const auto* spec_model = std::get_if<spec::LumpedModel>(&scene.model);
  if (spec_model == nullptr) return Failed(report, spec::FailureKind::kInvalidModel, "scene has no lumped model");
  if (parameter_values_si.size() != scene.parameters.size()) {
    return Failed(report, spec::FailureKind::kInvalidModel, absl::StrCat("got ", parameter_values_si.size(), " parameter values for ",
                                       scene.parameters.size(), " scene parameters"));
  }
  absl::StatusOr<LumpedModel> assembled =
      LumpedModel::Assemble(*spec_model, parameter_values_si);
  if (!assembled.ok()) {
    return Failed(report, spec::FailureKind::kInvalidModel, std::string(assembled.status().message()));
  }
  const LumpedModel& m = *assembled;

  std::vector<OutputPlan> plans;
  bool needs_acceleration = false;
  for (const spec::Output& out : scene.outputs) {
    OutputPlan plan;
    if (const auto* d = std::get_if<spec::ElementDeflectionOutput>(&out.kind)) {
      plan.kind = OutputPlan::Kind::kDeflection;
      plan.element = d->element;
    } else if (const auto* a = std::get_if<spec::BodyAccelerationOutput>(&out.kind)) {
      using Q = spec::BodyAccelerationOutput::Quantity;
      plan.kind = a->quantity == Q::kDisplacement ? OutputPlan::Kind::kDisplacement
                  : a->quantity == Q::kVelocity   ? OutputPlan::Kind::kVelocity
                                                  : OutputPlan::Kind::kAcceleration;
      plan.body = a->body;
      plan.offset_x_m = a->offset_m.x.Resolve(parameter_values_si);
      plan.offset_y_m = a->offset_m.y.Resolve(parameter_values_si);
      plan.axis = a->axis;
      needs_acceleration = needs_acceleration || plan.kind == OutputPlan::Kind::kAcceleration;
    } else {
      return Failed(report, spec::FailureKind::kInvalidModel, absl::StrCat("output \"", out.name,
                                         "\" is not available for a lumped scene (only "
                                         "element_deflection and body_acceleration, _displacement and _velocity are)"));
    }
    plans.push_back(plan);
    spec::OutputValues values;
    values.name = out.name;
    values.series_labels = {out.name};
    values.series.assign(1, std::vector<double>());
    values.series[0].reserve(report.times_s.size());
    report.outputs.push_back(std::move(values));
  }
  if (plans.empty()) return report;  // nothing requested: nothing computed

  Eigen::VectorXd a(m.num_coordinates());
  auto at_instant = [&](double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
    if (needs_acceleration) m.Acceleration(t, q, v, &a);
    for (size_t o = 0; o < plans.size(); ++o) {
      const OutputPlan& plan = plans[o];
      // A body point's displacement, velocity and acceleration are the same
      // linear map of q, q' and q''.
      const double value =
          plan.kind == OutputPlan::Kind::kDeflection
              ? m.Deflection(plan.element, q, t)
              : m.PointMotion(plan.body, plan.offset_x_m, plan.offset_y_m, plan.axis,
                                    plan.kind == OutputPlan::Kind::kDisplacement ? q
                                    : plan.kind == OutputPlan::Kind::kVelocity   ? v
                                                                                 : a);
      if (!std::isfinite(value)) {
        return spec::AnalysisFailure::Of(
            spec::FailureKind::kNonFiniteValue,
            absl::StrFormat("output \"%s\" is not finite at t = %.9g s", scene.outputs[o].name, t));
      }
      report.outputs[o].series[0].push_back(value);
    }
    return spec::AnalysisFailure::Ok();
  };
  const spec::AnalysisFailure failure =
      IntegrateLumped(m, report.times_s, scene.integrator, options, at_instant, &report.counters);
  if (!failure.ok()) return Failed(report, failure);
  return report;
}

}  // namespace mbopt::lumped
