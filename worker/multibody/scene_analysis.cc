#include "worker/multibody/scene_analysis.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <variant>

#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "worker/multibody/assembly.h"
#include "spec/layout.h"
#include "worker/multibody/flexible_link.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/kinematic_sensitivity.h"
#include "worker/multibody/kinematic_analysis.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/parameter_derivatives.h"
#include "worker/multibody/static_equilibrium.h"

namespace mbopt::multibody {
namespace {

using Quantity = spec::MultibodyOutput::Quantity;

Eigen::Vector2d Resolve(const spec::Vec2& v, const std::vector<double>& p) {
  return Eigen::Vector2d(v.x.Resolve(p), v.y.Resolve(p));
}

// The body of node `node` of flexible link `link`: the links' nodes follow
// the rigid bodies, link after link (CompileModel).
int LinkNode(const spec::MultibodyModel& m, int link, int node) {
  int first = static_cast<int>(m.bodies.size());
  for (int j = 0; j < link; ++j) first += m.flexible_links[static_cast<size_t>(j)].elements + 1;
  return first + node;
}
int LinkFirstElement(const spec::MultibodyModel& m, int link) {
  int first = 0;
  for (int j = 0; j < link; ++j) first += m.flexible_links[static_cast<size_t>(j)].elements;
  return first;
}

Point PointOf(const spec::MultibodyModel& m, const spec::MarkerRef& ref, const std::vector<double>& p) {
  if (ref.link >= 0) {
    const spec::MultibodyFlexibleLink& link = m.flexible_links[static_cast<size_t>(ref.link)];
    return Point{LinkNode(m, ref.link, ref.marker == 0 ? 0 : link.elements), Eigen::Vector2d::Zero(),
                 link.name + (ref.marker == 0 ? ".a" : ".b")};
  }
  if (ref.input >= 0) return Point{kGround, Eigen::Vector2d::Zero(), m.inputs[static_cast<size_t>(ref.input)].name, ref.input};
  const std::vector<spec::LinkPoint>& markers =
      ref.body < 0 ? m.ground_markers : m.bodies[static_cast<size_t>(ref.body)].markers;
  const spec::LinkPoint& marker = markers[static_cast<size_t>(ref.marker)];
  return Point{ref.body < 0 ? kGround : ref.body, Resolve(marker.position_m, p), marker.name};
}

Profile ProfileOf(const spec::MultibodyDriver& d, const std::vector<double>& p) {
  Profile profile;
  switch (d.profile) {
    case spec::MultibodyDriver::Profile::kConstantRate:
      profile.kind = Profile::Kind::kConstantRate;
      profile.start = d.start.Resolve(p);
      profile.rate = d.rate.Resolve(p);
      break;
    case spec::MultibodyDriver::Profile::kPolynomial:
      profile.kind = Profile::Kind::kPolynomial;
      for (const spec::Number& c : d.coefficients) profile.coefficients.push_back(c.Resolve(p));
      break;
    case spec::MultibodyDriver::Profile::kTabulated:
      profile.kind = Profile::Kind::kTabulated;
      profile.table = CubicSpline(d.times_s, d.values);
      break;
    case spec::MultibodyDriver::Profile::kHarmonic:
      profile.kind = Profile::Kind::kHarmonic;
      profile.start = d.start.Resolve(p);
      profile.amplitude = d.amplitude.Resolve(p);
      profile.angular_frequency_rad_per_s = d.angular_frequency_rad_per_s.Resolve(p);
      profile.phase_rad = d.phase_rad.Resolve(p);
      break;
  }
  return profile;
}

bool NeedsMultipliers(const spec::Scene& scene) {
  for (const spec::Output& o : scene.outputs) {
    const auto* m = std::get_if<spec::MultibodyOutput>(&o.kind);
    if (m != nullptr && (m->quantity == Quantity::kJointReaction || m->quantity == Quantity::kDriverEffort)) {
      return true;
    }
  }
  return false;
}

// The value of output `o` in the state `s`.
double OutputValue(const Mechanism& mech, const spec::MultibodyModel& sm, const spec::MultibodyOutput& o,
                   const std::vector<double>& p, const MotionSample& s, Eigen::MatrixXd* phi_q) {
  const int axis = o.axis == spec::Axis::kX ? 0 : 1;
  switch (o.quantity) {
    case Quantity::kMarkerPosition: return mech.PointPosition(PointOf(sm, o.marker, p), s.q, s.t_s)[axis];
    case Quantity::kMarkerVelocity: return mech.PointVelocity(PointOf(sm, o.marker, p), s.q, s.v, s.t_s)[axis];
    case Quantity::kMarkerAcceleration:
      return mech.PointAcceleration(PointOf(sm, o.marker, p), s.q, s.v, s.a, s.t_s)[axis];
    case Quantity::kJointCoordinate: return mech.JointCoordinate(o.joint, s.q);
    case Quantity::kJointRate: return mech.JointRate(o.joint, s.q, s.v);
    case Quantity::kJointReaction: {
      // Force on body b (or, with b ground, minus the force on body a): the
      // generalized constraint force -Phi_q^T lambda of the joint's rows on
      // that body's x and y.
      const Joint& joint = mech.model().joints[static_cast<size_t>(o.joint)];
      const int body = joint.b.body != kGround ? joint.b.body : joint.a.body;
      const double sign = joint.b.body != kGround ? 1.0 : -1.0;
      mech.ConstraintJacobian(s.t_s, s.q, phi_q);
      const int first = mech.first_row_of_joint(o.joint);
      int rows = 0;
      while (first + rows < mech.num_constraints() && !mech.is_driver_row(first + rows) &&
             mech.joint_of_row(first + rows) == o.joint) {
        ++rows;
      }
      const Eigen::VectorXd force =
          -phi_q->block(first, 3 * body, rows, 2).transpose() * s.lambda.segment(first, rows);
      return sign * force[axis];
    }
    case Quantity::kDriverEffort: {
      for (size_t d = 0; d < mech.model().drivers.size(); ++d) {
        if (mech.model().drivers[d].joint == o.joint) return -s.lambda[mech.row_of_driver(static_cast<int>(d))];
      }
      return NAN;
    }
    case Quantity::kSpringLength: return mech.SpringLength(o.spring, s.q, s.t_s);
    case Quantity::kSpringForce: return mech.SpringTension(o.spring, s.q, s.v, s.t_s);
    case Quantity::kKineticEnergy: return mech.KineticEnergy(s.v);
    case Quantity::kPotentialEnergy: return mech.PotentialEnergy(s.q, s.t_s);
  }
  return NAN;
}

// Bending stress at every node of a flexible link (one value per node, Pa):
// M r / I for the solid circular section (r = sqrt(A / pi), I = A^2 / 4 pi),
// M the bending moment at the node (-Ma of the element that starts there,
// Mb of the one that ends there; their mean at interior nodes).
bool NodeStresses(const Mechanism& mech, const spec::MultibodyModel& sm, int link, const std::vector<double>& p,
                  const Eigen::VectorXd& q, const Eigen::VectorXd& v, std::vector<double>* stresses) {
  const spec::MultibodyFlexibleLink& l = sm.flexible_links[static_cast<size_t>(link)];
  const double area = l.section.area_m2.Resolve(p);
  const double fibre_per_inertia = std::sqrt(area / std::numbers::pi) / (area * area / (4.0 * std::numbers::pi));
  const int first = LinkFirstElement(sm, link);
  stresses->assign(static_cast<size_t>(l.elements + 1), 0.0);
  std::vector<int> count(static_cast<size_t>(l.elements + 1), 0);
  for (int e = 0; e < l.elements; ++e) {
    BeamLoads loads;
    if (!mech.BeamEndLoads(first + e, q, v, &loads)) return false;
    (*stresses)[static_cast<size_t>(e)] -= loads.moment_a_n_m;
    (*stresses)[static_cast<size_t>(e + 1)] += loads.moment_b_n_m;
    ++count[static_cast<size_t>(e)];
    ++count[static_cast<size_t>(e + 1)];
  }
  for (size_t k = 0; k < stresses->size(); ++k) (*stresses)[k] *= fibre_per_inertia / count[k];
  return true;
}

}  // namespace

absl::StatusOr<Model> CompileModel(const spec::Scene& scene, const std::vector<double>& p) {
  const auto& sm = std::get<spec::MultibodyModel>(scene.model);
  Model m;
  for (const spec::RigidBody& b : sm.bodies) {
    m.bodies.push_back(Body{b.name, b.mass_kg.Resolve(p), b.inertia_kg_m2.Resolve(p), Resolve(b.position_m, p),
                            b.angle_rad.Resolve(p)});
  }
  // Structural damping C = beta K with beta = 2 zeta / omega_1, omega_1 the
  // lowest first bending frequency over the flexible links, each alone with
  // its ends pinned, or clamped at a driven end (as the linkage model's).
  double damping_s = 0.0;
  if (scene.effects.structural_damping_ratio.has_value() && !sm.flexible_links.empty()) {
    double lowest = INFINITY;
    for (size_t i = 0; i < sm.flexible_links.size(); ++i) {
      const spec::MultibodyFlexibleLink& l = sm.flexible_links[i];
      bool clamped = false;
      for (const spec::MultibodyDriver& d : sm.drivers) {
        const spec::MultibodyJoint& j = sm.joints[static_cast<size_t>(d.joint)];
        clamped = clamped || j.a.link == static_cast<int>(i) || j.b.link == static_cast<int>(i);
      }
      const double area = l.section.area_m2.Resolve(p), length = l.length_m.Resolve(p);
      const double ei = l.section.youngs_modulus_pa.Resolve(p) * area * area / (4.0 * std::numbers::pi);
      const double rho_a = l.section.density_kg_per_m3.Resolve(p) * area;
      // First roots of the clamped-pinned and pinned-pinned beams, (beta L)^2.
      const double root = clamped ? 15.4182057 : std::numbers::pi * std::numbers::pi;
      lowest = std::min(lowest, root * std::sqrt(ei / (rho_a * std::pow(length, 4))));
    }
    if (std::isfinite(lowest) && lowest > 0.0) damping_s = 2.0 * *scene.effects.structural_damping_ratio / lowest;
  }
  for (const spec::MultibodyFlexibleLink& l : sm.flexible_links) {
    FlexibleLinkSpec link;
    link.name = l.name;
    link.start_m = Resolve(l.start_m, p);
    link.angle_rad = l.angle_rad.Resolve(p);
    link.length_m = l.length_m.Resolve(p);
    const double area = l.section.area_m2.Resolve(p), modulus = l.section.youngs_modulus_pa.Resolve(p);
    link.axial_stiffness_n = modulus * area;
    link.bending_stiffness_n_m2 = modulus * area * area / (4.0 * std::numbers::pi);
    link.mass_per_length_kg_per_m = l.section.density_kg_per_m3.Resolve(p) * area;
    if (l.rotary_inertia) {
      link.rotary_inertia_per_length_kg_m = l.section.density_kg_per_m3.Resolve(p) * area * area / (4.0 * std::numbers::pi);
    }
    link.damping_s = damping_s;
    link.elements = l.elements;
    AddFlexibleLink(link, &m);
  }
  for (const spec::MultibodyJoint& j : sm.joints) {
    Joint joint;
    joint.name = j.name;
    switch (j.kind) {
      case spec::JointKind::kRevolute: joint.kind = JointKind::kRevolute; break;
      case spec::JointKind::kPrismatic: joint.kind = JointKind::kPrismatic; break;
      case spec::JointKind::kFixed: joint.kind = JointKind::kFixed; break;
      case spec::JointKind::kPointOnLine: joint.kind = JointKind::kPointOnLine; break;
    }
    joint.a = PointOf(sm, j.a, p);
    joint.b = PointOf(sm, j.b, p);
    joint.axis_angle_rad = j.axis_angle_rad.Resolve(p);
    if (j.initial_value) joint.initial_value = j.initial_value->Resolve(p);
    if (j.initial_rate) joint.initial_rate = j.initial_rate->Resolve(p);
    m.joints.push_back(std::move(joint));
  }
  for (const spec::MultibodyDriver& d : sm.drivers) m.drivers.push_back(Driver{d.joint, ProfileOf(d, p)});
  for (const spec::MultibodyInput& in : sm.inputs) {
    Eigen::Vector2d direction(in.direction_x, in.direction_y);
    m.inputs.push_back(InputPoint{in.name, Resolve(in.position_m, p), direction, ProfileOf(in.displacement, p)});
  }
  for (const spec::MultibodySpring& s : sm.springs) {
    SpringDamper spring;
    spring.name = s.name;
    spring.a = PointOf(sm, s.a, p);
    spring.b = PointOf(sm, s.b, p);
    spring.free_length_m = s.free_length_m.Resolve(p);
    spring.stiffness_n_per_m = s.stiffness_n_per_m.Resolve(p);
    spring.damping_n_s_per_m = s.damping_n_s_per_m.Resolve(p);
    spring.actuator_force_n = s.actuator_force_n.Resolve(p);
    spring.deflection_curve = LinearTable{s.deflection_m, s.deflection_force_n};
    spring.velocity_curve = LinearTable{s.velocity_m_per_s, s.velocity_force_n};
    m.springs.push_back(std::move(spring));
  }
  for (const spec::RotationalSpring& r : sm.rotational_springs) {
    m.rotational_springs.push_back(RotationalSpringDamper{r.name, r.joint, r.stiffness_n_m_per_rad.Resolve(p),
                                                          r.damping_n_m_s_per_rad.Resolve(p),
                                                          r.free_angle_rad.Resolve(p)});
  }
  for (const spec::MultibodyPointForce& f : sm.point_forces) {
    m.point_forces.push_back(PointForce{PointOf(sm, f.at, p), Resolve(f.force_n, p),
                                        f.factor ? std::optional<Profile>(ProfileOf(*f.factor, p)) : std::nullopt});
  }
  for (const spec::MultibodyTorque& t : sm.torques) {
    m.torques.push_back(BodyTorque{t.body, t.torque_n_m.Resolve(p),
                                   t.factor ? std::optional<Profile>(ProfileOf(*t.factor, p)) : std::nullopt});
  }
  if (scene.effects.gravity_m_per_s2.has_value()) m.gravity_m_per_s2 = Resolve(*scene.effects.gravity_m_per_s2, p);
  if (absl::Status valid = m.Validate(); !valid.ok()) return valid;
  return m;
}

namespace {

// The model rebuilt at p_k + step and p_k - step, for sensitivities.
struct Variant {
  std::vector<double> p;
  Model model;
  std::unique_ptr<Mechanism> mechanism;  // refers to `model`: a Variant never moves
  Assembly assembled;
};
struct Perturbed {
  std::unique_ptr<Variant> plus, minus;
  std::unique_ptr<ParameterDerivativeModel> derivative;  // null: the equations are differenced
  double step = 0.0;
  double magnitude = 1.0;  // |p_k|, or 1 for p_k = 0
};

constexpr double kRelativeParameterStep = 1e-5;

// Builds and assembles one variant; empty string on success, else why not.
std::string MakeVariant(const spec::Scene& scene, std::vector<double> p, const AssemblyOptions& options,
                        const Mechanism& nominal, std::unique_ptr<Variant>* out) {
  auto v = std::make_unique<Variant>();
  v->p = std::move(p);
  absl::StatusOr<Model> model = CompileModel(scene, v->p);
  if (!model.ok()) return std::string(model.status().message());
  v->model = *std::move(model);
  v->mechanism = std::make_unique<Mechanism>(v->model);
  if (v->mechanism->num_constraints() != nominal.num_constraints()) return "the constraint rows change with the parameter";
  v->assembled = Assemble(*v->mechanism, 0.0, options);
  if (!v->assembled.failure.ok()) return v->assembled.failure.reason;
  *out = std::move(v);
  return "";
}

// d output / dp along (state derivative, e_k): a central difference between
// the variants.
double OutputDerivative(const spec::MultibodyModel& sm, const spec::MultibodyOutput& o, const Perturbed& dp,
                        const MotionSample& s, const StateSensitivity& ds, Eigen::MatrixXd* phi_q) {
  const double h = dp.step;
  auto shifted = [&](double sign) {
    MotionSample x;
    x.t_s = s.t_s;
    x.q = s.q + sign * h * ds.q;
    x.v = s.v + sign * h * ds.v;
    x.a = s.a + sign * h * ds.a;
    if (s.lambda.size() > 0 && ds.lambda.size() == s.lambda.size()) x.lambda = s.lambda + sign * h * ds.lambda;
    return x;
  };
  const double plus = OutputValue(*dp.plus->mechanism, sm, o, dp.plus->p, shifted(1.0), phi_q);
  const double minus = OutputValue(*dp.minus->mechanism, sm, o, dp.minus->p, shifted(-1.0), phi_q);
  return (plus - minus) / (2.0 * h);
}

// d stress / dp at every node of flexible link `link`, as OutputDerivative:
// the variants carry the parameter's effect on the section (area, modulus,
// hence stiffness and fibre distance) and on the reference geometry, the
// shifted states that through the motion. False if nodes coincide.
bool StressDerivatives(const spec::MultibodyModel& sm, int link, const Perturbed& dp, const MotionSample& s,
                       const StateSensitivity& ds, std::vector<double>* derivatives) {
  const double h = dp.step;
  std::vector<double> plus, minus;
  if (!NodeStresses(*dp.plus->mechanism, sm, link, dp.plus->p, s.q + h * ds.q, s.v + h * ds.v, &plus) ||
      !NodeStresses(*dp.minus->mechanism, sm, link, dp.minus->p, s.q - h * ds.q, s.v - h * ds.v, &minus)) {
    return false;
  }
  derivatives->resize(plus.size());
  for (size_t j = 0; j < plus.size(); ++j) (*derivatives)[j] = (plus[j] - minus[j]) / (2.0 * h);
  return true;
}

// The most turns a driver may make between two instants: an analysis that
// follows the motion needs a step per turn at least, and more than the
// step budget's worth can never end within it.
std::string DriverTooFast(const Model& model, const std::vector<double>& instants_s, std::int64_t max_steps) {
  if (max_steps <= 0) return "";
  std::vector<double> times;
  if (instants_s.empty() || instants_s.front() > 0.0) times.push_back(0.0);
  times.insert(times.end(), instants_s.begin(), instants_s.end());
  for (const Driver& d : model.drivers) {
    const Joint& joint = model.joints[static_cast<size_t>(d.joint)];
    if (joint.kind != JointKind::kRevolute) continue;
    for (size_t i = 1; i < times.size(); ++i) {
      const Profile::Value from = d.profile.At(times[i - 1]), to = d.profile.At(times[i]);
      // A harmonic driver may come back to where it was: its largest rate
      // over the interval bounds the angle it sweeps.
      double swept_rad = std::abs(to.q - from.q);
      if (d.profile.kind == Profile::Kind::kHarmonic) {
        swept_rad = std::max(swept_rad, std::abs(d.profile.amplitude * d.profile.angular_frequency_rad_per_s) *
                                            (times[i] - times[i - 1]));
      }
      const double turns = swept_rad / (2.0 * std::numbers::pi);
      if (!(turns <= static_cast<double>(max_steps))) {
        return absl::StrFormat(
            "driver of joint '%s' turns %.3g times between t = %.6g s and %.6g s, more than the step budget of %d "
            "steps (integrator.max_steps) could follow",
            joint.name, turns, times[i - 1], times[i], max_steps);
      }
    }
  }
  return "";
}

// The one analysis; with `parameters`, also the output derivatives.
void Analyze(const spec::Scene& scene, const std::vector<double>& p, const std::vector<int>* parameters,
             budget::AnalysisBudget* budget, MultibodySensitivityResult* result) {
  spec::AnalysisReport& report = result->report;
  report.times_s = scene.time_grid.Instants();
  report.formulation = spec::Formulation::kKinematic;
  if (!std::holds_alternative<spec::MultibodyModel>(scene.model) || p.size() != scene.parameters.size()) {
    report.Fail(spec::FailureKind::kInvalidModel,
                absl::StrFormat("expected a multibody scene and %d parameter values", scene.parameters.size()));
    return;
  }
  const auto& sm = std::get<spec::MultibodyModel>(scene.model);
  absl::StatusOr<Model> model = CompileModel(scene, p);
  if (!model.ok()) {
    report.Fail(spec::FailureKind::kInvalidModel, std::string(model.status().message()));
    return;
  }
  if (const std::string why = DriverTooFast(*model, report.times_s, scene.integrator.max_steps); !why.empty()) {
    report.Fail(spec::FailureKind::kInvalidModel, why);
    return;
  }
  for (size_t k = 0; k < scene.outputs.size(); ++k) {
    const spec::Output& o = scene.outputs[k];
    const auto* stress = std::get_if<spec::BendingStressOutput>(&o.kind);
    if (!std::holds_alternative<spec::MultibodyOutput>(o.kind) &&
        (stress == nullptr || stress->link < 0 || stress->link >= static_cast<int>(sm.flexible_links.size()))) {
      report.Fail(spec::FailureKind::kInvalidModel, absl::StrFormat("output '%s' is not a multibody output", o.name));
      return;
    }
    const spec::OutputShape shape = spec::OutputShapeOf(scene, static_cast<int>(k));
    spec::OutputValues values;
    values.name = o.name;
    values.series_labels = shape.series_labels;
    values.series.assign(static_cast<size_t>(shape.series), std::vector<double>());
    for (std::vector<double>& series : values.series) series.reserve(report.times_s.size());
    report.outputs.push_back(std::move(values));
  }
  if (report.outputs.empty()) return;  // nothing requested: nothing computed

  const bool sensitivities = parameters != nullptr && !parameters->empty();
  AssemblyOptions assembly_options;
  assembly_options.budget = budget;
  // Variants are differenced: close every assembly to round-off.
  if (sensitivities) assembly_options.polish_iterations = 3;
  const Mechanism mechanism(*model);
  // Flexible links start with rigid-body velocities: v = T w, w holding per
  // rigid body its (x', y', phi') and per link its end a's (x', y') and its
  // angular rate.
  Eigen::MatrixXd velocity_basis;
  if (!sm.flexible_links.empty()) {
    const int n = mechanism.num_coordinates();
    const int rigid = static_cast<int>(sm.bodies.size());
    velocity_basis = Eigen::MatrixXd::Zero(n, 3 * rigid + 3 * static_cast<int>(sm.flexible_links.size()));
    velocity_basis.topLeftCorner(3 * rigid, 3 * rigid).setIdentity();
    const Eigen::VectorXd q0 = mechanism.InitialGuess();
    for (size_t i = 0; i < sm.flexible_links.size(); ++i) {
      SetRigidLinkVelocityColumns(q0, LinkNode(sm, static_cast<int>(i), 0), sm.flexible_links[i].elements,
                                  3 * rigid + 3 * static_cast<int>(i), &velocity_basis);
    }
    assembly_options.velocity_basis = &velocity_basis;
  }
  const Assembly assembled = Assemble(mechanism, 0.0, assembly_options);
  report.counters.newton_iterations += assembled.newton_iterations;
  if (!assembled.failure.ok()) {
    report.Fail(assembled.failure.kind, assembled.failure.reason);
    return;
  }
  if (!assembled.redundant.empty()) {
    report.Fail(spec::FailureKind::kInvalidModel,
                absl::StrFormat("redundant constraints at joint(s) %s: a planar loop closes with one revolute "
                                "joint fewer, or with a point-on-line joint",
                                absl::StrJoin(assembled.redundant, ", ")));
    return;
  }
  const bool is_static = sm.analysis == spec::MultibodyModel::Analysis::kStaticEquilibrium;
  std::vector<Perturbed> perturbed;
  if (sensitivities) {
    for (const int index : *parameters) {
      Perturbed dp;
      const double value = p[static_cast<size_t>(index)];
      dp.magnitude = value != 0.0 ? std::abs(value) : 1.0;
      dp.step = kRelativeParameterStep * dp.magnitude;
      std::vector<double> plus = p, minus = p;
      plus[static_cast<size_t>(index)] += dp.step;
      minus[static_cast<size_t>(index)] -= dp.step;
      std::string why = MakeVariant(scene, std::move(plus), assembly_options, mechanism, &dp.plus);
      if (why.empty()) why = MakeVariant(scene, std::move(minus), assembly_options, mechanism, &dp.minus);
      if (!why.empty()) {
        result->unavailable = absl::StrFormat("parameter '%s' +- %g: %s", scene.parameters[static_cast<size_t>(index)].name,
                                              dp.step, why);
        perturbed.clear();
        break;
      }
      dp.derivative = ParameterDerivativeModel::Of(*model, dp.plus->model, dp.minus->model, dp.step);
      perturbed.push_back(std::move(dp));
    }
  }
  const bool with_derivatives = !perturbed.empty();
  if (with_derivatives) {
    std::vector<std::vector<std::vector<double>>> per_parameter(report.outputs.size());
    for (size_t k = 0; k < report.outputs.size(); ++k) per_parameter[k].resize(report.outputs[k].series.size());
    result->output_derivatives.assign(perturbed.size(), per_parameter);
  }
  // The motion starts at t = 0; the grid may start later.
  std::vector<double> times;
  if (report.times_s.empty() || report.times_s.front() > 0.0) times.push_back(0.0);
  times.insert(times.end(), report.times_s.begin(), report.times_s.end());
  size_t next_instant = 0;
  Eigen::MatrixXd phi_q;
  std::vector<ParameterPerturbation> perturbations;
  for (const Perturbed& dp : perturbed) {
    perturbations.push_back(ParameterPerturbation{dp.plus->mechanism.get(), dp.minus->mechanism.get(), dp.step,
                                                  dp.magnitude,
                                                  dp.derivative != nullptr ? &dp.derivative->system() : nullptr});
  }
  const bool driven = assembled.degrees_of_freedom == 0;
  std::vector<StateSensitivity> kinematic;  // work space of the driven and static paths
  const MotionCallback record = [&](const MotionSample& s) {
    if (budget != nullptr) {
      if (spec::AnalysisFailure f = budget->Check(s.t_s); !f.ok()) return f;
    }
    if (next_instant >= report.times_s.size() || s.t_s != report.times_s[next_instant]) {
      return spec::AnalysisFailure::Ok();
    }
    ++next_instant;
    std::vector<double> stresses;
    for (size_t k = 0; k < scene.outputs.size(); ++k) {
      if (const auto* stress = std::get_if<spec::BendingStressOutput>(&scene.outputs[k].kind)) {
        if (!NodeStresses(mechanism, sm, stress->link, p, s.q, s.v, &stresses)) {
          return spec::AnalysisFailure::Of(spec::FailureKind::kNonFiniteValue,
                                           absl::StrFormat("flexible link nodes coincide at t = %.6g s", s.t_s));
        }
        for (size_t j = 0; j < stresses.size(); ++j) report.outputs[k].series[j].push_back(stresses[j]);
        continue;
      }
      const auto& o = std::get<spec::MultibodyOutput>(scene.outputs[k].kind);
      const double value = OutputValue(mechanism, sm, o, p, s, &phi_q);
      if (!std::isfinite(value)) {
        if (!mechanism.FailureReason().empty()) {
          return spec::AnalysisFailure::Of(spec::FailureKind::kModelValidity, mechanism.FailureReason());
        }
        return spec::AnalysisFailure::Of(
            spec::FailureKind::kNonFiniteValue,
            absl::StrFormat("output '%s' is not finite at t = %.6g s", scene.outputs[k].name, s.t_s));
      }
      report.outputs[k].series[0].push_back(value);
    }
    if (!with_derivatives || !result->unavailable.empty()) return spec::AnalysisFailure::Ok();
    // Forward dynamics brings the state's derivatives; a static
    // equilibrium's come from its equations by the implicit function
    // theorem, a driven mechanism's from its differentiated constraint
    // equations.
    const std::vector<StateSensitivity>* ds = &s.sensitivities;
    if (ds->size() != perturbed.size()) {
      const bool found = is_static ? StaticStateSensitivities(mechanism, perturbations, s, &kinematic)
                                   : driven && KinematicStateSensitivities(mechanism, perturbations, s, &kinematic);
      if (!found) {
        result->unavailable = absl::StrFormat("no state derivative at t = %.6g s", s.t_s);
        return spec::AnalysisFailure::Ok();
      }
      ds = &kinematic;
    }
    for (size_t i = 0; i < perturbed.size(); ++i) {
      for (size_t k = 0; k < scene.outputs.size(); ++k) {
        std::vector<std::vector<double>>& series = result->output_derivatives[i][k];
        if (const auto* stress = std::get_if<spec::BendingStressOutput>(&scene.outputs[k].kind)) {
          if (!StressDerivatives(sm, stress->link, perturbed[i], s, (*ds)[i], &stresses)) {
            result->unavailable = absl::StrFormat(
                "flexible link nodes coincide in a perturbed state at t = %.6g s (parameter '%s')", s.t_s,
                scene.parameters[static_cast<size_t>((*parameters)[i])].name);
            return spec::AnalysisFailure::Ok();
          }
          for (size_t j = 0; j < stresses.size(); ++j) series[j].push_back(stresses[j]);
          continue;
        }
        const auto& o = std::get<spec::MultibodyOutput>(scene.outputs[k].kind);
        series[0].push_back(OutputDerivative(sm, o, perturbed[i], s, (*ds)[i], &phi_q));
      }
    }
    return spec::AnalysisFailure::Ok();
  };
  spec::AnalysisFailure outcome;
  if (is_static) {
    report.formulation = spec::Formulation::kStatic;
    StaticCounters counters;
    StaticOptions options;
    options.budget = budget;
    outcome = RunStaticEquilibrium(mechanism, assembled.q, times, options, record, &counters);
    report.counters.position_solves += counters.position_solves;
    report.counters.newton_iterations += counters.newton_iterations;
    report.counters.rhs_evaluations += counters.residual_evaluations;
    report.counters.jacobian_evaluations += counters.newton_matrices;
  } else if (driven) {
    KinematicOptions options;
    options.inverse_dynamics = NeedsMultipliers(scene);
    options.budget = budget;
    report.formulation = options.inverse_dynamics ? spec::Formulation::kKinetostatic : spec::Formulation::kKinematic;
    KinematicCounters counters;
    outcome = RunKinematics(mechanism, assembled.q, times, options, record, &counters);
    report.counters.position_solves += counters.position_solves;
    report.counters.newton_iterations += counters.newton_iterations;
  } else {
    report.formulation = spec::Formulation::kDynamic;
    ForwardDynamicsOptions options = ForwardDynamicsOptions::Of(scene.integrator, budget);
    ForwardDynamicsCounters counters;
    ForwardSensitivityInput input;
    if (with_derivatives) {
      input.parameters = perturbations;
      for (const Perturbed& dp : perturbed) {
        input.q0.push_back((dp.plus->assembled.q - dp.minus->assembled.q) / (2.0 * dp.step));
        input.v0.push_back((dp.plus->assembled.v - dp.minus->assembled.v) / (2.0 * dp.step));
      }
    }
    outcome = IntegrateForward(mechanism, 0.0, assembled.q, assembled.v, times, options, record, &counters,
                               with_derivatives ? &input : nullptr);
    report.counters.time_steps = counters.steps;
    report.counters.rhs_evaluations = counters.residual_evaluations;
    report.counters.jacobian_evaluations = counters.jacobian_evaluations;
    report.counters.newton_iterations += counters.nonlinear_iterations;
  }
  if (!outcome.ok()) report.Fail(outcome.kind, outcome.reason);
  if (!report.ok() || !result->unavailable.empty()) result->output_derivatives.clear();
  if (sensitivities && !report.ok() && result->unavailable.empty()) result->unavailable = "the analysis failed";
}

}  // namespace

spec::AnalysisReport AnalyzeMultibodyScene(const spec::Scene& scene, const std::vector<double>& p,
                                           budget::AnalysisBudget* budget) {
  MultibodySensitivityResult result;
  Analyze(scene, p, nullptr, budget, &result);
  return std::move(result.report);
}

MultibodySensitivityResult AnalyzeMultibodySceneWithSensitivities(const spec::Scene& scene,
                                                                  const std::vector<double>& p,
                                                                  const std::vector<int>& parameters,
                                                                  budget::AnalysisBudget* budget) {
  MultibodySensitivityResult result;
  Analyze(scene, p, &parameters, budget, &result);
  return result;
}

std::string MultibodySensitivityUnavailable(const spec::Scene& scene) {
  const auto* sm = std::get_if<spec::MultibodyModel>(&scene.model);
  if (sm == nullptr) return "not a multibody scene";
  return "";
}

}  // namespace mbopt::multibody
