#include "worker/lumped/lumped_sensitivity.h"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <functional>
#include <variant>

#include "absl/strings/str_cat.h"
#include "worker/lumped/lumped_model.h"
#include "worker/lumped/lumped_sensitivity_problem.h"

namespace mbopt::lumped {
namespace {

using sensitivity_internal::ParameterDerivative;
using sensitivity_internal::SensitivityProblem;
using sensitivity_internal::SensitivityRecorder;

// The analytic derivatives below take a mass, inertia, stiffness or damping
// bound directly to a parameter (derivative 1); one computed from it by an
// expression has no simulator sensitivity (yet).
bool Uses(const spec::Number& number, int parameter) { return number.DependsOn(parameter); }
bool ThroughExpression(const spec::Number& number, int parameter) {
  return number.expression != nullptr && number.DependsOn(parameter);
}

spec::AnalysisReport Failed(spec::AnalysisReport report, spec::FailureKind kind, std::string reason) {
  report.Fail(kind, std::move(reason));
  return report;
}
spec::AnalysisReport Failed(spec::AnalysisReport report, std::string reason) {
  return Failed(std::move(report), spec::FailureKind::kInvalidModel, std::move(reason));
}

}  // namespace

std::string LumpedSensitivityUnavailable(const spec::Scene& scene,
                                         const std::vector<int>& parameters) {
  const auto* m = std::get_if<spec::LumpedModel>(&scene.model);
  if (m == nullptr) return "simulator sensitivities are available only for lumped scenes";
  for (int p : parameters) {
    const std::string name = p >= 0 && p < static_cast<int>(scene.parameters.size())
                                 ? scene.parameters[static_cast<size_t>(p)].name
                                 : absl::StrCat("#", p);
    auto where = [&](const std::string& what) {
      return absl::StrCat("parameter \"", name, "\" sets ", what,
                          ", which has no simulator sensitivity (only masses, inertias, "
                          "stiffnesses and dampings have)");
    };
    for (const spec::Body& b : m->bodies) {
      if (ThroughExpression(b.mass_kg, p) || ThroughExpression(b.inertia_kg_m2, p)) {
        return where(absl::StrCat("the mass or inertia of body ", b.name, " through an expression"));
      }
    }
    for (const spec::SpringDamper& e : m->elements) {
      if (ThroughExpression(e.stiffness_n_per_m, p) || ThroughExpression(e.damping_n_s_per_m, p)) {
        return where(absl::StrCat("the stiffness or damping of element ", e.name, " through an expression"));
      }
      for (const spec::Attachment* at : {&e.a, &e.b}) {
        if (Uses(at->offset_m.x, p) || Uses(at->offset_m.y, p)) {
          return where(absl::StrCat("an attachment offset of element ", e.name));
        }
      }
    }
    for (const spec::GroundInput& in : m->inputs) {
      const spec::CosineBump& b = in.bump;
      if (Uses(b.height_m, p) || Uses(b.length_m, p) || Uses(b.speed_m_per_s, p) ||
          Uses(b.start_time_s, p) || Uses(in.delay_s, p)) {
        return where(absl::StrCat("ground input ", in.name));
      }
    }
    for (const spec::Output& out : scene.outputs) {
      if (const auto* a = std::get_if<spec::BodyAccelerationOutput>(&out.kind)) {
        if (Uses(a->offset_m.x, p) || Uses(a->offset_m.y, p)) {
          return where(absl::StrCat("the offset of output ", out.name));
        }
      }
    }
  }
  return "";
}

LumpedSensitivityResult SimulateLumpedWithSensitivities(
    const spec::Scene& scene, const std::vector<double>& parameter_values_si,
    const std::vector<int>& parameters, const LumpedSensitivityOptions& options) {
  LumpedSensitivityResult result;
  spec::AnalysisReport& report = result.report;
  report.formulation = spec::Formulation::kDynamic;
  report.times_s = scene.time_grid.Instants();
  const auto* spec_model = std::get_if<spec::LumpedModel>(&scene.model);
  if (spec_model == nullptr) {
    report = Failed(report, "scene has no lumped model");
    return result;
  }
  if (const std::string why = LumpedSensitivityUnavailable(scene, parameters); !why.empty()) {
    report = Failed(report, why);
    return result;
  }
  if (parameter_values_si.size() != scene.parameters.size() || parameters.empty()) {
    report = Failed(report, absl::StrCat("got ", parameter_values_si.size(),
                                         " parameter values for ", scene.parameters.size(),
                                         " scene parameters and ", parameters.size(),
                                         " sensitivity parameters"));
    return result;
  }
  absl::StatusOr<LumpedModel> assembled =
      LumpedModel::Assemble(*spec_model, parameter_values_si);
  if (!assembled.ok()) {
    report = Failed(report, std::string(assembled.status().message()));
    return result;
  }
  const LumpedModel& m = *assembled;
  const int n = m.num_coordinates();
  const int ns = static_cast<int>(parameters.size());

  SensitivityProblem problem;
  problem.model = &m;
  problem.n = n;
  problem.inverse_mass = m.mass_diagonal().cwiseInverse();
  problem.minv_k = problem.inverse_mass.asDiagonal() * m.stiffness();
  problem.minv_c = problem.inverse_mass.asDiagonal() * m.damping();
  problem.zero = Eigen::VectorXd::Zero(n);
  problem.force = Eigen::VectorXd::Zero(n);
  problem.rhs = Eigen::VectorXd::Zero(n);
  problem.input_deflection.assign(m.elements().size(), 0.0);
  problem.input_rate.assign(m.elements().size(), 0.0);
  problem.budget = options.budget;
  for (int p : parameters) {
    ParameterDerivative d;
    d.mass_diagonal = Eigen::VectorXd::Zero(n);
    d.stiffness = Eigen::MatrixXd::Zero(n, n);
    d.damping = Eigen::MatrixXd::Zero(n, n);
    for (size_t b = 0; b < spec_model->bodies.size(); ++b) {
      const spec::Body& body = spec_model->bodies[b];
      const int body_index = static_cast<int>(b);
      if (Uses(body.mass_kg, p)) {
        for (spec::Dof dof : {spec::Dof::kX, spec::Dof::kY}) {
          const int i = m.CoordinateOf(body_index, dof);
          if (i >= 0) d.mass_diagonal[i] += 1.0;
        }
      }
      if (Uses(body.inertia_kg_m2, p)) {
        const int i = m.CoordinateOf(body_index, spec::Dof::kRotation);
        if (i >= 0) d.mass_diagonal[i] += 1.0;
      }
    }
    for (size_t e = 0; e < spec_model->elements.size(); ++e) {
      const Eigen::VectorXd& g = m.elements()[e].gradient;
      if (Uses(spec_model->elements[e].stiffness_n_per_m, p)) {
        d.stiffness += g * g.transpose();
        d.stiffness_elements.push_back(static_cast<int>(e));
      }
      if (Uses(spec_model->elements[e].damping_n_s_per_m, p)) {
        d.damping += g * g.transpose();
        d.damping_elements.push_back(static_cast<int>(e));
      }
    }
    problem.derivatives.push_back(std::move(d));
  }

  // Outputs to evaluate (as SimulateLumped).
  struct Plan {
    bool deflection = true;
    spec::BodyAccelerationOutput::Quantity quantity = spec::BodyAccelerationOutput::Quantity::kAcceleration;
    int index = -1;
    double ox = 0, oy = 0;
    spec::Axis axis = spec::Axis::kY;
  };
  std::vector<Plan> plans;
  for (const spec::Output& out : scene.outputs) {
    Plan plan;
    if (const auto* d = std::get_if<spec::ElementDeflectionOutput>(&out.kind)) {
      plan.index = d->element;
    } else if (const auto* a = std::get_if<spec::BodyAccelerationOutput>(&out.kind)) {
      plan.deflection = false;
      plan.quantity = a->quantity;
      plan.index = a->body;
      plan.ox = a->offset_m.x.Resolve(parameter_values_si);
      plan.oy = a->offset_m.y.Resolve(parameter_values_si);
      plan.axis = a->axis;
    } else {
      report = Failed(report, absl::StrCat("output \"", out.name,
                                           "\" is not available for a lumped scene"));
      return result;
    }
    plans.push_back(plan);
    spec::OutputValues values;
    values.name = out.name;
    values.series_labels = {out.name};
    values.series.assign(1, std::vector<double>());
    report.outputs.push_back(std::move(values));
  }
  result.output_derivatives.assign(static_cast<size_t>(ns),
                                   std::vector<std::vector<double>>(plans.size()));

  // Tolerances as IntegrateLumped for either method.
  const spec::IntegratorSettings& settings = scene.integrator;
  const Eigen::VectorXd inverse_root_mass = problem.inverse_mass.cwiseSqrt();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> modes(
      inverse_root_mass.asDiagonal() * m.stiffness() * inverse_root_mass.asDiagonal(),
      Eigen::EigenvaluesOnly);
  const double omega_max = std::sqrt(std::max(0.0, modes.eigenvalues().maxCoeff()));
  std::vector<double> pbar(static_cast<size_t>(ns));
  for (int k = 0; k < ns; ++k) {
    const double value = std::abs(parameter_values_si[static_cast<size_t>(parameters[k])]);
    pbar[static_cast<size_t>(k)] = value > 0.0 ? value : 1.0;
  }

  // Appends the outputs and their derivatives at instant t from the state
  // (q, q') and sensitivity(k) -> (s, s') of parameter k.
  using Quantity = spec::BodyAccelerationOutput::Quantity;
  bool need_acceleration = false;
  for (const Plan& plan : plans) {
    need_acceleration = need_acceleration || (!plan.deflection && plan.quantity == Quantity::kAcceleration);
  }
  Eigen::VectorXd q(n), v(n), qddot(n), dqddot(n);
  const SensitivityRecorder record = [&](double t, const Eigen::Ref<const Eigen::VectorXd>& state,
                                         const std::function<const double*(int)>& sensitivity) {
    q = state.head(n);
    v = state.tail(n);
    m.Acceleration(t, q, v, &qddot);
    for (size_t o = 0; o < plans.size(); ++o) {
      const Plan& plan = plans[o];
      // A body point's displacement, velocity and acceleration: the same
      // linear map of q, q' and q'' (and of their sensitivities below).
      const double value = plan.deflection
                               ? m.Deflection(plan.index, q, t)
                               : m.PointMotion(plan.index, plan.ox, plan.oy, plan.axis,
                                                     plan.quantity == Quantity::kDisplacement ? q
                                                     : plan.quantity == Quantity::kVelocity   ? v
                                                                                              : qddot);
      report.outputs[o].series[0].push_back(value);
    }
    for (int k = 0; k < ns; ++k) {
      const double* sk = sensitivity(k);
      const Eigen::Map<const Eigen::VectorXd> sq(sk, n), sv(sk + n, n);
      if (need_acceleration) problem.AccelerationDerivative(k, t, q, v, qddot, sq, sv, dqddot);
      for (size_t o = 0; o < plans.size(); ++o) {
        const Plan& plan = plans[o];
        const double derivative =
            plan.deflection ? m.elements()[static_cast<size_t>(plan.index)].gradient.dot(sq)
            : plan.quantity == Quantity::kDisplacement
                ? m.PointMotion(plan.index, plan.ox, plan.oy, plan.axis, sq)
            : plan.quantity == Quantity::kVelocity
                ? m.PointMotion(plan.index, plan.ox, plan.oy, plan.axis, sv)
                : m.PointMotion(plan.index, plan.ox, plan.oy, plan.axis, dqddot);
        result.output_derivatives[static_cast<size_t>(k)][o].push_back(derivative);
      }
    }
  };

  if (options.method == LumpedSensitivityOptions::Method::kAugmentedSystem) {
    const spec::AnalysisFailure failure =
        sensitivity_internal::IntegrateAugmented(&problem, settings, options, omega_max, pbar, report.times_s, record,
                           &report.counters, &result.counters);
    if (!failure.ok()) {
      report = Failed(report, failure.kind, failure.reason);
      result.output_derivatives.clear();
    }
    return result;
  }
  const spec::AnalysisFailure failure =
      sensitivity_internal::IntegrateWithSensitivityModule(&problem, settings, options, omega_max, pbar, report.times_s,
                                     record, &report.counters, &result.counters);
  if (!failure.ok()) {
    report = Failed(report, failure.kind, failure.reason);
    result.output_derivatives.clear();
  }
  return result;
}

}  // namespace mbopt::lumped
