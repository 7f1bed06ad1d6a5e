#include "worker/spatial/spatial_scene_analysis.h"

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <variant>

#include "absl/strings/str_format.h"
#include "spec/layout.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/kinematic_sensitivity.h"
#include "worker/spatial/euler_angles.h"
#include "worker/spatial/euler_parameters.h"
#include "worker/spatial/redundant_constraints.h"
#include "worker/spatial/spatial_assembly.h"
#include "worker/spatial/spatial_force_elements.h"
#include "worker/spatial/spatial_kinematics.h"
#include "worker/spatial/spatial_reactions.h"
#include "worker/spatial/spatial_static_equilibrium.h"
#include "worker/spatial/spatial_system.h"

namespace mbopt::spatial {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Quantity = spec::SpatialOutput::Quantity;

Vector3d Resolve(const spec::Vec3& v, const std::vector<double>& p) {
  return Vector3d(v.x.Resolve(p), v.y.Resolve(p), v.z.Resolve(p));
}

EulerSequence SequenceOf(const int axes[3]) { return {axes[0], axes[1], axes[2]}; }

Matrix3d OrientationMatrix(const spec::Orientation& o, const std::vector<double>& p) {
  switch (o.form) {
    case spec::Orientation::Form::kIdentity: return Matrix3d::Identity();
    case spec::Orientation::Form::kAxisAngle:
      return AxisAngle(Vector3d(o.axis[0], o.axis[1], o.axis[2]), o.angles_rad[0].Resolve(p));
    case spec::Orientation::Form::kEulerAngles:
      return RotationOfEulerAngles(SequenceOf(o.sequence), Vector3d(o.angles_rad[0].Resolve(p),
                                                                    o.angles_rad[1].Resolve(p),
                                                                    o.angles_rad[2].Resolve(p)));
  }
  return Matrix3d::Identity();
}

const spec::SpatialMarker& MarkerOf(const spec::SpatialModel& sm, const spec::MarkerRef& ref) {
  const std::vector<spec::SpatialMarker>& markers =
      ref.body < 0 ? sm.ground_markers : sm.bodies[static_cast<size_t>(ref.body)].markers;
  return markers[static_cast<size_t>(ref.marker)];
}

Frame FrameOf(const spec::SpatialModel& sm, const spec::MarkerRef& ref, const std::vector<double>& p) {
  const spec::SpatialMarker& marker = MarkerOf(sm, ref);
  Frame f;
  f.body = ref.body < 0 ? kGround : ref.body;
  f.position_m = Resolve(marker.position_m, p);
  f.axes = OrientationMatrix(marker.orientation, p);
  return f;
}

Point PointOf(const spec::SpatialModel& sm, const spec::MarkerRef& ref, const std::vector<double>& p) {
  const Frame f = FrameOf(sm, ref, p);
  return Point{f.body, f.position_m};
}

multibody::Profile ProfileOf(const spec::MultibodyDriver& d, const std::vector<double>& p) {
  multibody::Profile profile;
  using K = multibody::Profile::Kind;
  switch (d.profile) {
    case spec::MultibodyDriver::Profile::kConstantRate:
      profile.kind = K::kConstantRate;
      profile.start = d.start.Resolve(p);
      profile.rate = d.rate.Resolve(p);
      break;
    case spec::MultibodyDriver::Profile::kPolynomial:
      profile.kind = K::kPolynomial;
      for (const spec::Number& c : d.coefficients) profile.coefficients.push_back(c.Resolve(p));
      break;
    case spec::MultibodyDriver::Profile::kTabulated:
      profile.kind = K::kTabulated;
      profile.table = multibody::CubicSpline(d.times_s, d.values);
      break;
    case spec::MultibodyDriver::Profile::kHarmonic:
      profile.kind = K::kHarmonic;
      profile.start = d.start.Resolve(p);
      profile.amplitude = d.amplitude.Resolve(p);
      profile.angular_frequency_rad_per_s = d.angular_frequency_rad_per_s.Resolve(p);
      profile.phase_rad = d.phase_rad.Resolve(p);
      break;
  }
  return profile;
}

Joint::Kind JointKindOf(spec::SpatialJointKind kind) {
  using S = spec::SpatialJointKind;
  switch (kind) {
    case S::kSpherical: return Joint::Kind::kSpherical;
    case S::kRevolute: return Joint::Kind::kRevolute;
    case S::kUniversal: return Joint::Kind::kUniversal;
    case S::kFixed: return Joint::Kind::kFixed;
    case S::kPrismatic: return Joint::Kind::kPrismatic;
    case S::kCylindrical: return Joint::Kind::kCylindrical;
    case S::kPlanar: return Joint::Kind::kPlanar;
    case S::kPointOnLine: return Joint::Kind::kPointOnLine;
    case S::kPointOnPlane: return Joint::Kind::kPointOnPlane;
  }
  return Joint::Kind::kSpherical;
}

// The value of output `o` in the state `s`.
double OutputValue(const SpatialSystem& system, const Model& model, const spec::SpatialModel& sm,
                   const spec::SpatialOutput& o, const std::vector<double>& p, const multibody::MotionSample& s,
                   const Eigen::VectorXd& lambda) {
  const int axis = static_cast<int>(o.axis);
  switch (o.quantity) {
    case Quantity::kMarkerPosition: return system.PointPosition(PointOf(sm, o.marker, p), s.q)[axis];
    case Quantity::kMarkerVelocity: return system.PointVelocity(PointOf(sm, o.marker, p), s.q, s.v)[axis];
    case Quantity::kMarkerAcceleration:
      return system.PointAcceleration(PointOf(sm, o.marker, p), s.q, s.v, s.a)[axis];
    case Quantity::kBodyOrientation: {
      // The integrator holds |p| = 1 to its tolerance; A(p) / |p|^2 is the
      // rotation of the unit parameters p / |p|.
      const Eigen::Vector4d e = s.q.segment<4>(SpatialSystem::kCoordinatesPerBody * o.body + 3);
      return EulerAnglesOf(SequenceOf(o.sequence), system.BodyRotation(o.body, s.q) / e.squaredNorm())[o.angle];
    }
    case Quantity::kJointCoordinate:
      return o.linear ? system.JointTranslation(o.joint, s.q) : system.JointAngle(o.joint, s.q);
    case Quantity::kJointRate:
      return o.linear ? system.JointTranslationRate(o.joint, s.q, s.v) : system.JointAngleRate(o.joint, s.q, s.v);
    case Quantity::kJointSlide: return system.JointTranslation(o.joint, s.q);
    case Quantity::kJointSlideRate: return system.JointTranslationRate(o.joint, s.q, s.v);
    case Quantity::kSpringLength:
    case Quantity::kSpringForce: {
      const SpringDamper& spring = model.springs[static_cast<size_t>(o.spring)];
      const Vector3d d = system.PointPosition(spring.b, s.q) - system.PointPosition(spring.a, s.q);
      const double length = d.norm();
      if (o.quantity == Quantity::kSpringLength) return length;
      const Vector3d d_dot = system.PointVelocity(spring.b, s.q, s.v) - system.PointVelocity(spring.a, s.q, s.v);
      return SpringTension(spring, length, d.dot(d_dot) / length, false);
    }
    case Quantity::kKineticEnergy: return system.KineticEnergy(s.q, s.v);
    case Quantity::kPotentialEnergy: return system.PotentialEnergy(s.q);
    case Quantity::kBodyAngularVelocity:
      return (o.body_axes ? system.BodyAngularVelocity(o.body, s.q, s.v) : system.AngularVelocity(o.body, s.q, s.v))[axis];
    case Quantity::kJointReaction: return JointReactionOf(system, o.joint, s.t_s, s.q, lambda).force_n[axis];
    case Quantity::kJointReactionMoment: return JointReactionOf(system, o.joint, s.t_s, s.q, lambda).moment_n_m[axis];
    case Quantity::kDriverEffort:
      // Driver rows are written so that their derivative along the driven
      // coordinate is 1 at the solution: -lambda is the generalized force.
      return -lambda[system.row_of_driver(o.driver)];
    case Quantity::kBushingForce: return BushingLoadOf(model, o.bushing, s.q, s.v).force_n[axis];
    case Quantity::kBushingMoment: return BushingLoadOf(model, o.bushing, s.q, s.v).moment_n_m[axis];
    case Quantity::kRotationalSpringTorque: return system.RotationalSpringTorque(o.spring, s.q, s.v);
  }
  return NAN;
}

}  // namespace

absl::StatusOr<Model> CompileSpatialModel(const spec::Scene& scene, const std::vector<double>& p) {
  const auto& sm = std::get<spec::SpatialModel>(scene.model);
  Model m;
  for (const spec::SpatialBody& b : sm.bodies) {
    Body body;
    body.name = b.name;
    body.mass_kg = b.mass_kg.Resolve(p);
    if (b.components) {
      const spec::Number* c = b.inertia_components_kg_m2;
      const double xy = c[3].Resolve(p), xz = c[4].Resolve(p), yz = c[5].Resolve(p);
      body.inertia_kg_m2 << c[0].Resolve(p), xy, xz, xy, c[1].Resolve(p), yz, xz, yz, c[2].Resolve(p);
    } else {
      const Matrix3d axes = OrientationMatrix(b.principal_axes, p);
      body.inertia_kg_m2 = axes * Resolve(b.principal_moments_kg_m2, p).asDiagonal() * axes.transpose();
      // Exactly symmetric, whatever the rounding of the products above.
      body.inertia_kg_m2 = 0.5 * (body.inertia_kg_m2 + body.inertia_kg_m2.transpose()).eval();
    }
    body.position_m = Resolve(b.position_m, p);
    body.orientation = OrientationMatrix(b.orientation, p);
    body.velocity_m_per_s = Resolve(b.velocity_m_per_s, p);
    body.angular_velocity_rad_per_s = Resolve(b.angular_velocity_rad_per_s, p);
    m.bodies.push_back(std::move(body));
  }
  for (const spec::SpatialJoint& j : sm.joints) {
    m.joints.push_back(Joint{j.name, JointKindOf(j.kind), FrameOf(sm, j.a, p), FrameOf(sm, j.b, p)});
  }
  for (const spec::MultibodyDriver& d : sm.drivers) m.drivers.push_back(Driver{d.joint, ProfileOf(d, p), d.slide});
  for (const spec::SpatialSpring& s : sm.springs) {
    SpringDamper spring;
    spring.name = s.name;
    spring.a = PointOf(sm, s.a, p);
    spring.b = PointOf(sm, s.b, p);
    spring.stiffness_n_per_m = s.stiffness_n_per_m.Resolve(p);
    spring.free_length_m = s.free_length_m.Resolve(p);
    spring.damping_n_s_per_m = s.damping_n_s_per_m.Resolve(p);
    spring.actuator_force_n = s.actuator_force_n.Resolve(p);
    spring.deflection_curve = multibody::LinearTable{s.deflection_m, s.deflection_force_n};
    spring.velocity_curve = multibody::LinearTable{s.velocity_m_per_s, s.velocity_force_n};
    m.springs.push_back(std::move(spring));
  }
  if (sm.gravity_m_per_s2) m.gravity_m_per_s2 = Resolve(*sm.gravity_m_per_s2, p);
  auto factor_of = [&](const std::optional<spec::TimeFactor>& f) {
    return f ? std::optional<multibody::Profile>(ProfileOf(*f, p)) : std::nullopt;
  };
  for (const spec::SpatialPointForce& f : sm.point_forces) {
    m.point_forces.push_back(
        PointForce{f.name, PointOf(sm, f.at, p), Resolve(f.force_n, p), f.body_axes, factor_of(f.factor)});
  }
  for (const spec::SpatialTorque& t : sm.torques) {
    m.torques.push_back(BodyTorque{t.name, t.body, Resolve(t.torque_n_m, p), t.body_axes, factor_of(t.factor)});
  }
  for (const spec::SpatialRotationalSpring& r : sm.rotational_springs) {
    m.rotational_springs.push_back(RotationalSpringDamper{r.name, r.joint, r.stiffness_n_m_per_rad.Resolve(p),
                                                          r.damping_n_m_s_per_rad.Resolve(p),
                                                          r.free_angle_rad.Resolve(p)});
  }
  for (const spec::SpatialBushing& b : sm.bushings) {
    m.bushings.push_back(Bushing{b.name, FrameOf(sm, b.a, p), FrameOf(sm, b.b, p), Resolve(b.stiffness_n_per_m, p),
                                 Resolve(b.damping_n_s_per_m, p), Resolve(b.rotational_stiffness_n_m_per_rad, p),
                                 Resolve(b.rotational_damping_n_m_s_per_rad, p)});
  }
  if (absl::Status valid = m.Validate(); !valid.ok()) return valid;
  return m;
}

namespace {

// The model rebuilt at p_k + step and p_k - step, for sensitivities.
struct Variant {
  std::vector<double> p;
  Model model;
  std::unique_ptr<SpatialSystem> system;  // refers to `model`: a Variant never moves
  SpatialAssembly assembled;
};
struct Perturbed {
  std::unique_ptr<Variant> plus, minus;
  double step = 0.0;
  double magnitude = 1.0;  // |p_k|, or 1 for p_k = 0
};

// As the planar scenes' (worker/multibody/scene_analysis.cc): small enough
// for the central differences' truncation (h^2), large enough for the
// equations' round-off (eps / h).
constexpr double kRelativeParameterStep = 1e-5;

// Builds and assembles one variant; empty string on success, else why not.
std::string MakeVariant(const spec::Scene& scene, std::vector<double> p, const SpatialAssemblyOptions& options,
                        const SpatialSystem& nominal, std::unique_ptr<Variant>* out) {
  auto v = std::make_unique<Variant>();
  v->p = std::move(p);
  absl::StatusOr<Model> model = CompileSpatialModel(scene, v->p);
  if (!model.ok()) return std::string(model.status().message());
  v->model = *std::move(model);
  v->system = std::make_unique<SpatialSystem>(v->model);
  if (v->system->num_constraints() != nominal.num_constraints()) return "the constraint rows change with the parameter";
  v->assembled = AssembleSpatial(*v->system, 0.0, options);
  if (!v->assembled.failure.ok()) return v->assembled.failure.reason;
  *out = std::move(v);
  return "";
}

// d output / dp along (state derivative, e_k): a central difference between
// the variants, each at the state moved along the derivative. Orientation
// outputs thus follow the Euler parameters' derivatives; multipliers (for
// reactions and efforts) are the variants' inverse dynamics of the moved
// states.
// `is_static`: the multipliers are the equilibrium's own and move with
// their sensitivities; a motion's come from inverse dynamics of each
// variant's state.
double OutputDerivative(const spec::SpatialModel& sm, const spec::SpatialOutput& o, const Perturbed& dp,
                        const multibody::MotionSample& s, const multibody::StateSensitivity& ds,
                        bool needs_multipliers, bool is_static) {
  const double h = dp.step;
  auto value = [&](const Variant& variant, double sign) {
    multibody::MotionSample x;
    x.t_s = s.t_s;
    x.q = s.q + sign * h * ds.q;
    x.v = s.v + sign * h * ds.v;
    x.a = s.a + sign * h * ds.a;
    const Eigen::VectorXd lambda = is_static           ? Eigen::VectorXd(s.lambda + sign * h * ds.lambda)
                                   : needs_multipliers ? Multipliers(*variant.system, x.t_s, x.q, x.v, x.a)
                                                       : Eigen::VectorXd();
    return OutputValue(*variant.system, variant.model, sm, o, variant.p, x, lambda);
  };
  return (value(*dp.plus, 1.0) - value(*dp.minus, -1.0)) / (2.0 * h);
}

// The one analysis; with `parameters`, also the output derivatives.
void Analyze(const spec::Scene& scene, const std::vector<double>& p, const std::vector<int>* parameters,
             budget::AnalysisBudget* budget, SpatialSensitivityResult* result) {
  spec::AnalysisReport& report = result->report;
  report.times_s = scene.time_grid.Instants();
  report.formulation = spec::Formulation::kDynamic;
  if (!std::holds_alternative<spec::SpatialModel>(scene.model) || p.size() != scene.parameters.size()) {
    report.Fail(spec::FailureKind::kInvalidModel,
                absl::StrFormat("expected a spatial scene and %d parameter values", scene.parameters.size()));
    return;
  }
  const auto& sm = std::get<spec::SpatialModel>(scene.model);
  for (size_t k = 0; k < scene.outputs.size(); ++k) {
    const spec::Output& o = scene.outputs[k];
    if (!std::holds_alternative<spec::SpatialOutput>(o.kind)) {
      report.Fail(spec::FailureKind::kInvalidModel, absl::StrFormat("output '%s' is not a spatial output", o.name));
      return;
    }
    const spec::OutputShape shape = spec::OutputShapeOf(scene, static_cast<int>(k));
    spec::OutputValues values;
    values.name = o.name;
    values.series_labels = shape.series_labels;
    values.series.assign(1, std::vector<double>());
    values.series[0].reserve(report.times_s.size());
    report.outputs.push_back(std::move(values));
  }
  if (report.outputs.empty()) return;  // nothing requested: nothing computed
  absl::StatusOr<Model> model = CompileSpatialModel(scene, p);
  if (!model.ok()) {
    report.Fail(spec::FailureKind::kInvalidModel, std::string(model.status().message()));
    return;
  }
  const bool sensitivities = parameters != nullptr && !parameters->empty();
  SpatialAssemblyOptions assembly_options;
  // Variants are differenced: close every assembly to round-off.
  if (sensitivities) assembly_options.polish_iterations = 2;
  const SpatialSystem system(*model);
  const SpatialAssembly assembled = AssembleSpatial(system, 0.0, assembly_options);
  report.counters.newton_iterations += assembled.newton_iterations;
  if (!assembled.failure.ok()) {
    report.Fail(assembled.failure.kind, assembled.failure.reason);
    return;
  }
  // Reactions and efforts come from the multipliers, solved per instant
  // from the motion (inverse dynamics) only when an output asks for them.
  // With redundant joints the multipliers belong to combinations of rows
  // (redundant_constraints.h): a joint's reaction is not unique.
  bool needs_multipliers = false;
  for (const spec::Output& output : scene.outputs) {
    const auto quantity = std::get<spec::SpatialOutput>(output.kind).quantity;
    const bool multiplier_output = quantity == Quantity::kJointReaction ||
                                   quantity == Quantity::kJointReactionMoment || quantity == Quantity::kDriverEffort;
    if (multiplier_output && assembled.redundant_rows > 0) {
      report.Fail(spec::FailureKind::kInvalidModel,
                  absl::StrFormat("output '%s': the mechanism has %d redundant constraint equation(s), so its "
                                  "joints' reactions and drivers' efforts are not unique; ask for them in a "
                                  "mechanism without redundant joints (e.g. a spherical joint made a "
                                  "point-on-line one)",
                                  output.name, assembled.redundant_rows));
      return;
    }
    needs_multipliers |= multiplier_output;
  }
  const bool is_static = sm.analysis == spec::MultibodyModel::Analysis::kStaticEquilibrium;
  // The variants at p_k +- step_k: their equations are differenced (no
  // exact derivative models for spatial systems), their assemblies give the
  // start's derivatives.
  std::vector<Perturbed> perturbed;
  if (sensitivities && result->unavailable.empty()) {
    for (const int index : *parameters) {
      Perturbed dp;
      const double value = p[static_cast<size_t>(index)];
      dp.magnitude = value != 0.0 ? std::abs(value) : 1.0;
      dp.step = kRelativeParameterStep * dp.magnitude;
      std::vector<double> plus = p, minus = p;
      plus[static_cast<size_t>(index)] += dp.step;
      minus[static_cast<size_t>(index)] -= dp.step;
      std::string why = MakeVariant(scene, std::move(plus), assembly_options, system, &dp.plus);
      if (why.empty()) why = MakeVariant(scene, std::move(minus), assembly_options, system, &dp.minus);
      if (why.empty() && (dp.plus->assembled.degrees_of_freedom != assembled.degrees_of_freedom ||
                          dp.minus->assembled.degrees_of_freedom != assembled.degrees_of_freedom)) {
        why = "the degrees of freedom change with the parameter";
      }
      if (!why.empty()) {
        result->unavailable = absl::StrFormat("parameter '%s' +- %g: %s",
                                              scene.parameters[static_cast<size_t>(index)].name, dp.step, why);
        perturbed.clear();
        break;
      }
      perturbed.push_back(std::move(dp));
    }
  }
  const bool with_derivatives = !perturbed.empty();
  if (with_derivatives) {
    result->output_derivatives.assign(perturbed.size(),
                                      std::vector<std::vector<double>>(scene.outputs.size(), std::vector<double>()));
  }
  std::vector<multibody::ParameterPerturbation> perturbations;
  for (const Perturbed& dp : perturbed) {
    perturbations.push_back(
        multibody::ParameterPerturbation{dp.plus->system.get(), dp.minus->system.get(), dp.step, dp.magnitude, nullptr});
  }
  std::vector<multibody::StateSensitivity> kinematic;  // work space of the driven and static paths
  // Redundant joints: a static instant's rows are combined as its solve
  // combined them (its multipliers belong to that combination).
  Eigen::MatrixXd static_combination;
  size_t next_instant = 0;
  std::vector<double> bushing_bounds;
  const multibody::MotionCallback record = [&](const multibody::MotionSample& s) {
    if (budget != nullptr) {
      if (spec::AnalysisFailure f = budget->Check(s.t_s); !f.ok()) return f;
    }
    if (next_instant >= report.times_s.size() || s.t_s != report.times_s[next_instant]) {
      return spec::AnalysisFailure::Ok();
    }
    ++next_instant;
    // A kinematic analysis' motion does not read the bushings, so nothing
    // else stops it where their angles become singular (a motion's
    // integrator and a static solve do).
    if (!model->bushings.empty()) {
      bushing_bounds.resize(static_cast<size_t>(BushingAngleBoundCount(*model)));
      BushingAngleBounds(*model, s.q, bushing_bounds.data());
      for (size_t k = 0; k < bushing_bounds.size(); ++k) {
        if (!(bushing_bounds[k] >= 0.0)) {
          return spec::AnalysisFailure::Of(spec::FailureKind::kModelValidity,
                                           BushingAngleBoundReason(*model, static_cast<int>(k), s.t_s, s.q));
        }
      }
    }
    // A static solve brings its multipliers; a motion's come from inverse
    // dynamics.
    const Eigen::VectorXd lambda = is_static           ? s.lambda
                                   : needs_multipliers ? Multipliers(system, s.t_s, s.q, s.v, s.a)
                                                       : Eigen::VectorXd();
    for (size_t k = 0; k < scene.outputs.size(); ++k) {
      const auto& o = std::get<spec::SpatialOutput>(scene.outputs[k].kind);
      const double value = OutputValue(system, *model, sm, o, p, s, lambda);
      if (!std::isfinite(value)) {
        return spec::AnalysisFailure::Of(
            spec::FailureKind::kNonFiniteValue,
            absl::StrFormat("output '%s' is not finite at t = %.6g s", scene.outputs[k].name, s.t_s));
      }
      report.outputs[k].series[0].push_back(value);
    }
    if (!with_derivatives || !result->unavailable.empty()) return spec::AnalysisFailure::Ok();
    // Forward dynamics brings the state's derivatives; a driven
    // mechanism's come from its differentiated constraint equations, an
    // equilibrium's from its differentiated equilibrium equations.
    const std::vector<multibody::StateSensitivity>* ds = &s.sensitivities;
    if (ds->size() != perturbed.size()) {
      bool solved = false;
      if (assembled.redundant_rows > 0) {
        // The equations differentiated with independent combinations of
        // the rows (redundant_constraints.h): square and regular where the
        // full ones are not. A driven instant's rows hold exactly, so any
        // combination of full rank gives the same derivative; the one at
        // the instant's pose.
        Eigen::MatrixXd combination = static_combination;
        if (!is_static) {
          const IndependentConstraints now = IndependentCombination(system, s.t_s, s.q);
          if (now.ok) combination = now.combination;
        }
        if (combination.rows() > 0) {
          const CombinedConstraintSystem combined(system, combination);
          const CombinedPerturbations varied(perturbations, combination);
          solved = is_static ? multibody::StaticStateSensitivities(combined, varied.parameters(), s, &kinematic)
                             : multibody::KinematicStateSensitivities(combined, varied.parameters(), s, &kinematic);
        }
      } else {
        solved = is_static ? multibody::StaticStateSensitivities(system, perturbations, s, &kinematic)
                           : multibody::KinematicStateSensitivities(system, perturbations, s, &kinematic);
      }
      if (!solved) {
        result->unavailable = absl::StrFormat("no state derivative at t = %.6g s", s.t_s);
        return spec::AnalysisFailure::Ok();
      }
      ds = &kinematic;
    }
    for (size_t i = 0; i < perturbed.size(); ++i) {
      for (size_t k = 0; k < scene.outputs.size(); ++k) {
        const auto& o = std::get<spec::SpatialOutput>(scene.outputs[k].kind);
        result->output_derivatives[i][k].push_back(
            OutputDerivative(sm, o, perturbed[i], s, (*ds)[i], needs_multipliers, is_static));
      }
    }
    return spec::AnalysisFailure::Ok();
  };
  // The motion starts at t = 0; the grid may start later.
  std::vector<double> times;
  if (report.times_s.empty() || report.times_s.front() > 0.0) times.push_back(0.0);
  times.insert(times.end(), report.times_s.begin(), report.times_s.end());
  spec::AnalysisFailure outcome;
  if (is_static) {
    report.formulation = spec::Formulation::kStatic;
    multibody::StaticCounters counters;
    outcome = RunSpatialStaticEquilibrium(system, assembled, times, budget, record, &counters, &static_combination);
    report.counters.position_solves += counters.position_solves;
    report.counters.newton_iterations += counters.newton_iterations;
    report.counters.rhs_evaluations += counters.residual_evaluations;
  } else if (assembled.degrees_of_freedom == 0) {
    // Every degree of freedom driven: the motion follows from the
    // constraints alone, as in planar scenes (redundant rows included).
    report.formulation = spec::Formulation::kKinematic;
    SpatialKinematicOptions options;
    options.budget = budget;
    SpatialKinematicCounters counters;
    outcome = RunSpatialKinematics(system, assembled.q, times, options, record, &counters);
    report.counters.time_steps = counters.position_solves;
    report.counters.newton_iterations += counters.newton_iterations;
  } else {
    const multibody::ForwardDynamicsOptions options = multibody::ForwardDynamicsOptions::Of(scene.integrator, budget);
    multibody::ForwardDynamicsCounters counters;
    multibody::ForwardSensitivityInput input;
    if (with_derivatives) {
      input.parameters = perturbations;
      for (const Perturbed& dp : perturbed) {
        input.q0.push_back((dp.plus->assembled.q - dp.minus->assembled.q) / (2.0 * dp.step));
        input.v0.push_back((dp.plus->assembled.v - dp.minus->assembled.v) / (2.0 * dp.step));
      }
    }
    // Redundant joints: integrated as independent combinations of their
    // rows (redundant_constraints.h), every row checked along the way, the
    // sensitivities with them.
    RedundantIntegrationCounters redundant;
    outcome = assembled.redundant_rows > 0
                  ? IntegrateWithRedundantRows(system, assembled.independent_combination, 0.0, assembled.q,
                                               assembled.v, times, options, record, &counters, &redundant,
                                               with_derivatives ? &input : nullptr)
                  : multibody::IntegrateForward(system, 0.0, assembled.q, assembled.v, times, options, record,
                                                &counters, with_derivatives ? &input : nullptr);
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

spec::AnalysisReport AnalyzeSpatialScene(const spec::Scene& scene, const std::vector<double>& p,
                                         budget::AnalysisBudget* budget) {
  SpatialSensitivityResult result;
  Analyze(scene, p, nullptr, budget, &result);
  return std::move(result.report);
}

SpatialSensitivityResult AnalyzeSpatialSceneWithSensitivities(const spec::Scene& scene, const std::vector<double>& p,
                                                              const std::vector<int>& parameters,
                                                              budget::AnalysisBudget* budget) {
  SpatialSensitivityResult result;
  Analyze(scene, p, &parameters, budget, &result);
  return result;
}

}  // namespace mbopt::spatial
