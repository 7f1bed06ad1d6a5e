// A scene as domain types: what spec/io makes of a .scene.textproto after
// validation, free of protobuf. Names were checked and resolved to indices;
// numbers are SI. A Number may still be bound to a parameter: the engine
// resolves parameters per analysis, so one Scene serves every design point.
// Field meanings are documented in proto/mbopt/v1/scene.proto.
#pragma once

#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "spec/expression.h"
#include "spec/limits.h"

namespace mbopt::spec {

// A value in SI units: literal, the value of parameter `param`, or an
// arithmetic expression of parameters (spec/expression.h).
struct Number {
  double value = 0.0;  // used when param < 0 and there is no expression
  int param = -1;      // index into Scene::parameters
  std::shared_ptr<const Expression> expression;
  double Resolve(const std::vector<double>& parameter_values_si) const {
    if (expression != nullptr) return expression->Evaluate(parameter_values_si);
    return param >= 0 ? parameter_values_si[static_cast<size_t>(param)] : value;
  }
  // Whether the value changes with parameter `p`.
  bool DependsOn(int p) const {
    if (expression != nullptr) {
      const std::vector<int>& read = expression->parameters();
      return std::binary_search(read.begin(), read.end(), p);
    }
    return param == p;
  }
};

struct Vec2 {
  Number x, y;
};

struct Parameter {
  std::string name;
  double value_si = 0.0;        // default value, converted to SI
  std::string unit;             // as written; "" for SI
  double si_per_unit = 1.0;     // value_si = value_in_unit * si_per_unit
};

struct Effects {
  std::optional<Vec2> gravity_m_per_s2;
  std::optional<double> structural_damping_ratio;
};

// ---- linkage
struct Joint {
  std::string name;
  Vec2 position_m;
  bool ground = false;
};
struct Section {
  Number area_m2, youngs_modulus_pa, density_kg_per_m3;
};
struct LinkPoint {
  std::string name;
  Vec2 position_m;
};
struct Link {
  std::string name;
  int joint_a = -1, joint_b = -1;
  std::optional<Number> length_m;
  std::optional<Section> section;
  int flexible_elements = 0;  // 0: rigid
  bool rotary_inertia = false;
  std::vector<LinkPoint> points;
};
struct Driver {
  int link = -1;
  int pivot_joint = -1;
  std::optional<Number> start_angle_rad;
  Number angular_velocity_rad_per_s;
};
// How flexible links are analysed (docs/physics.md, section 3): small
// elastic motion on the rigid one (floating frame, the cheap model), or
// co-rotational beam elements whose nodes are bodies of the multibody
// engine, integrated as forward dynamics with the driver (accurate for large
// deflections and the frame's own rotation, many times the cost).
enum class FlexibleFormulation { kFloatingFrame, kCorotational };
struct LinkageModel {
  std::vector<Joint> joints;
  std::vector<Link> links;
  Driver driver;
  FlexibleFormulation flexible_formulation = FlexibleFormulation::kFloatingFrame;
};

// ---- lumped (small motion, linear)
enum class Dof { kX, kY, kRotation };
struct Body {
  std::string name;
  Number mass_kg, inertia_kg_m2;
  Vec2 position_m;
  std::vector<Dof> dofs;
};
struct Attachment {
  enum class Kind { kBody, kInput, kGround } kind = Kind::kGround;
  int index = -1;  // body or input index
  Vec2 offset_m;
};
struct SpringDamper {
  std::string name;
  Attachment a, b;
  double direction_x = 0.0, direction_y = 1.0;  // unit vector
  Number stiffness_n_per_m, damping_n_s_per_m;
};
struct CosineBump {
  Number height_m, length_m, speed_m_per_s, start_time_s;
};
struct GroundInput {
  std::string name;
  CosineBump bump;
  Number delay_s;
  double direction_x = 0.0, direction_y = 1.0;
};
struct LumpedModel {
  std::vector<Body> bodies;
  std::vector<SpringDamper> elements;
  std::vector<GroundInput> inputs;
};

// ---- multibody (any planar mechanism; worker/multibody)
// A marker of a body (body >= 0) or of ground (body = -1).
struct MarkerRef {
  int body = -1;
  int marker = -1;
  int input = -1;  // >= 0: a moving input point (MultibodyModel::inputs)
  int link = -1;   // >= 0: an end of MultibodyModel::flexible_links[link]; marker 0 is a, 1 is b
};
struct RigidBody {
  std::string name;
  Number mass_kg, inertia_kg_m2;
  Vec2 position_m;
  Number angle_rad;
  std::vector<LinkPoint> markers;  // in body axes, from the centre of mass
};
enum class JointKind { kRevolute, kPrismatic, kFixed, kPointOnLine };
struct MultibodyJoint {
  std::string name;
  JointKind kind = JointKind::kRevolute;
  MarkerRef a, b;
  Number axis_angle_rad;
  std::optional<Number> initial_value, initial_rate;
  bool linear() const { return kind == JointKind::kPrismatic || kind == JointKind::kPointOnLine; }
};
struct MultibodyDriver {
  int joint = -1;
  enum class Profile { kConstantRate, kPolynomial, kHarmonic, kTabulated } profile = Profile::kConstantRate;
  std::vector<double> times_s, values;  // kTabulated (literal table)
  Number start, rate;                 // kConstantRate; start is the mean for kHarmonic
  std::vector<Number> coefficients;   // kPolynomial
  Number amplitude, angular_frequency_rad_per_s, phase_rad;  // kHarmonic
  // Spatial scenes: the driver prescribes the joint's slide (m), not its
  // angle (a prismatic joint's, or a cylindrical joint's with `slide`).
  bool slide = false;
};
struct MultibodySpring {
  std::string name;
  MarkerRef a, b;
  Number free_length_m, stiffness_n_per_m, damping_n_s_per_m, actuator_force_n;
  // Force curves (literal tables; empty: the linear coefficient).
  std::vector<double> deflection_m, deflection_force_n, velocity_m_per_s, velocity_force_n;
};
struct RotationalSpring {
  std::string name;
  int joint = -1;
  Number stiffness_n_m_per_rad, damping_n_m_s_per_rad, free_angle_rad;
};
// A time factor of a force or torque: a driver's profile without a joint.
using TimeFactor = MultibodyDriver;
struct MultibodyPointForce {
  MarkerRef at;
  Vec2 force_n;
  std::optional<TimeFactor> factor;
};
struct MultibodyTorque {
  int body = -1;
  Number torque_n_m;
  std::optional<TimeFactor> factor;
};
struct MultibodyInput {
  std::string name;
  Vec2 position_m;
  double direction_x = 0.0, direction_y = 1.0;  // unit, literal
  MultibodyDriver displacement;                 // its profile (no joint)
};
// A flexible link of a multibody model: co-rotational beam elements.
struct MultibodyFlexibleLink {
  std::string name;
  Vec2 start_m;
  Number angle_rad, length_m;
  Section section;
  int elements = 4;
  bool rotary_inertia = false;
};
inline constexpr int kMaxFlexibleLinkElements = 200;

struct MultibodyModel {
  enum class Analysis { kFromDegreesOfFreedom, kStaticEquilibrium } analysis = Analysis::kFromDegreesOfFreedom;
  std::vector<MultibodyFlexibleLink> flexible_links;
  std::vector<MultibodyInput> inputs;
  std::vector<LinkPoint> ground_markers;
  std::vector<RigidBody> bodies;
  std::vector<MultibodyJoint> joints;
  std::vector<MultibodyDriver> drivers;
  std::vector<MultibodySpring> springs;
  std::vector<RotationalSpring> rotational_springs;
  std::vector<MultibodyPointForce> point_forces;
  std::vector<MultibodyTorque> torques;
};

// ---- spatial (rigid bodies in 3-D; worker/spatial)
struct Vec3 {
  Number x, y, z;
};
// A rotation as written (proto/mbopt/v1/scene.proto Orientation): from a
// frame's own axes to its parent's.
struct Orientation {
  enum class Form { kIdentity, kAxisAngle, kEulerAngles } form = Form::kIdentity;
  double axis[3] = {0.0, 0.0, 1.0};  // kAxisAngle: literal, unit length
  // kEulerAngles: the axes (0 x, 1 y, 2 z) of the three successive
  // rotations about the rotated axes.
  int sequence[3] = {2, 1, 0};
  Number angles_rad[3];  // kAxisAngle: angles_rad[0] only
};
struct SpatialMarker {
  std::string name;
  Vec3 position_m;
  Orientation orientation;
};
struct SpatialBody {
  std::string name;
  Number mass_kg;
  // Principal moments along `principal_axes` (body axes when identity), or,
  // with `components`, the tensor's six entries xx, yy, zz, xy, xz, yz.
  bool components = false;
  Vec3 principal_moments_kg_m2;
  Orientation principal_axes;
  Number inertia_components_kg_m2[6];
  Vec3 position_m;
  Orientation orientation;
  Vec3 velocity_m_per_s, angular_velocity_rad_per_s;
  std::vector<SpatialMarker> markers;
};
enum class SpatialJointKind {
  kSpherical, kRevolute, kUniversal, kFixed, kPrismatic, kCylindrical, kPlanar, kPointOnLine, kPointOnPlane
};
struct SpatialJoint {
  std::string name;
  SpatialJointKind kind = SpatialJointKind::kSpherical;
  MarkerRef a, b;  // body (-1: ground) and marker index
};
struct SpatialSpring {
  std::string name;
  MarkerRef a, b;
  Number free_length_m, stiffness_n_per_m, damping_n_s_per_m;
  // As MultibodySpring's: literal force curves (empty: the linear
  // coefficient) and a constant actuator force.
  std::vector<double> deflection_m, deflection_force_n, velocity_m_per_s, velocity_force_n;
  Number actuator_force_n;
};
// Loads: a force at a marker's origin, a torque on a body; components in
// world axes or in the axes of the body they act on.
struct SpatialPointForce {
  std::string name;
  MarkerRef at;
  Vec3 force_n;
  bool body_axes = false;
  std::optional<TimeFactor> factor;
};
struct SpatialTorque {
  std::string name;
  int body = -1;
  Vec3 torque_n_m;
  bool body_axes = false;
  std::optional<TimeFactor> factor;
};
// At a revolute or cylindrical joint's angle.
struct SpatialRotationalSpring {
  std::string name;
  int joint = -1;
  Number stiffness_n_m_per_rad, damping_n_m_s_per_rad, free_angle_rad;
};
// Between two markers, in marker a's axes.
struct SpatialBushing {
  std::string name;
  MarkerRef a, b;
  Vec3 stiffness_n_per_m, damping_n_s_per_m, rotational_stiffness_n_m_per_rad, rotational_damping_n_m_s_per_rad;
};
struct SpatialModel {
  std::vector<SpatialMarker> ground_markers;
  std::vector<SpatialBody> bodies;
  std::vector<SpatialJoint> joints;
  std::vector<MultibodyDriver> drivers;  // joint: an angle (revolute, cylindrical) or a slide (`slide`)
  std::vector<SpatialSpring> springs;
  std::optional<Vec3> gravity_m_per_s2;
  std::vector<SpatialPointForce> point_forces;
  std::vector<SpatialTorque> torques;
  std::vector<SpatialRotationalSpring> rotational_springs;
  std::vector<SpatialBushing> bushings;
  // Static: the equilibrium at each instant (worker/spatial/spatial_static_equilibrium.h).
  MultibodyModel::Analysis analysis = MultibodyModel::Analysis::kFromDegreesOfFreedom;
};

// ---- external (an analysis by a simulation code the worker declares as a
// driver; worker/external runs it, docs/external.md)
// A value given to one of the driver's declared parameters.
struct ExternalInput {
  std::string name;  // the driver's parameter
  Number value;      // SI
};
// Which driver runs the analysis is the worker's to check: its declared
// parameters are known only where it is declared.
struct ExternalModel {
  std::string driver;
  std::vector<ExternalInput> inputs;  // names unique
};

// ---- FMU
// An FMI 2.0 or 3.0 FMU run by the worker (worker/fmu). Its variables are checked
// against the FMU's model description when an analysis opens it.
struct FmuParameterBinding {
  std::string variable;  // the FMU's Real parameter
  Number value;          // SI
};
struct FmuModel {
  std::string path;  // the .fmu archive, absolute once the scene file was read
  // The archive's bytes when the study carries them (null otherwise), shared
  // by every copy of the scene; their SHA-256 (lowercase hex) and the
  // platforms they have binaries for (binaries/<platform>/, sorted), both
  // read from the bytes where the study was converted.
  std::shared_ptr<const std::string> archive;
  std::string archive_sha256;
  std::vector<std::string> platforms;
  bool co_simulation = false;
  std::vector<FmuParameterBinding> parameters;
  double communication_step_s = 0.0;  // co-simulation; 0: the FMU's default
};

// ---- outputs
enum class Axis { kX, kY, kZ };  // kZ: spatial scenes
struct PointPositionOutput { int link = -1; int point = -1; int joint = -1; Axis axis = Axis::kX; };  // link point, or joint if joint >= 0
struct LinkRotationOutput { int link = -1; };
struct ElementDeflectionOutput { int element = -1; };
// A lumped body point's motion: its acceleration, or (small motions about
// the equilibrium) its displacement or velocity.
struct BodyAccelerationOutput {
  enum class Quantity { kAcceleration, kDisplacement, kVelocity };
  int body = -1;
  Vec2 offset_m;
  Axis axis = Axis::kY;
  Quantity quantity = Quantity::kAcceleration;
};
struct BendingStressOutput { int link = -1; };
struct DriveTorqueOutput {};
struct MassOutput {};
// A named value (one per analysis, like mass) or a named time series of an
// external driver's results.
struct ExternalResultOutput {
  std::string name;  // as written in the results file
  bool series = false;
};
// An FMU scene's output: one of the FMU's Real variables.
struct FmuVariableOutput { std::string variable; };
// An output of a multibody scene. Reactions are the force body a's side of
// the joint exerts on body b; a driver's effort is the torque (revolute) or
// force (prismatic) it applies to body b.
struct MultibodyOutput {
  enum class Quantity {
    kMarkerPosition, kMarkerVelocity, kMarkerAcceleration,
    kJointCoordinate, kJointRate, kJointReaction, kDriverEffort,
    kSpringLength, kSpringForce, kKineticEnergy, kPotentialEnergy,
  } quantity = Quantity::kMarkerPosition;
  MarkerRef marker;
  int joint = -1;
  int spring = -1;
  Axis axis = Axis::kX;
  bool linear = false;  // joint outputs of a prismatic or point-on-line joint (m, N)
};

// An output of a spatial scene (world axes, SI). Joint coordinates: the
// angle of a revolute or cylindrical joint, the slide of a prismatic one;
// kJointSlide(Rate): a cylindrical or prismatic joint's slide.
struct SpatialOutput {
  enum class Quantity {
    kMarkerPosition, kMarkerVelocity, kMarkerAcceleration, kBodyOrientation,
    kJointCoordinate, kJointRate, kJointSlide, kJointSlideRate,
    kSpringLength, kSpringForce, kKineticEnergy, kPotentialEnergy,
    // Of the force elements and the multipliers (spatial_force_outputs.h):
    kBodyAngularVelocity, kJointReaction, kJointReactionMoment, kDriverEffort, kBushingForce, kBushingMoment,
    kRotationalSpringTorque,
  } quantity = Quantity::kMarkerPosition;
  MarkerRef marker;
  int body = -1, joint = -1, spring = -1;
  int bushing = -1;          // kBushingForce, kBushingMoment
  bool body_axes = false;    // kBodyAngularVelocity: in the body's axes, else world
  int driver = -1;           // kDriverEffort: torque (N m) or, `linear`, force (N) on the joint's body b
  Axis axis = Axis::kX;
  int sequence[3] = {2, 1, 0};  // kBodyOrientation: as Orientation::sequence
  int angle = 0;                // kBodyOrientation: 0, 1 or 2
  bool linear = false;          // joint outputs in m (a prismatic joint's coordinate, slides)
};

struct Output {
  std::string name;
  std::variant<PointPositionOutput, LinkRotationOutput, ElementDeflectionOutput,
               BodyAccelerationOutput, BendingStressOutput, DriveTorqueOutput, MassOutput, MultibodyOutput,
               ExternalResultOutput, FmuVariableOutput, SpatialOutput>
      kind;
};

struct TimeGrid {
  double start_s = 0.0, end_s = 0.0;
  int points = 1;  // 1: only end_s
  // The instants: `points` equally spaced from start_s to end_s inclusive
  // (only end_s when points == 1).
  std::vector<double> Instants() const;
};

// Which integrator a multibody scene's forward dynamics uses: IDAS's BDF on
// the stabilized index-2 form, or an explicit Runge-Kutta pair with
// projection onto the constraints (non-stiff planar multibody scenes only).
enum class IntegratorMethod { kIdas, kExplicitRungeKutta };

struct IntegratorSettings {
  IntegratorMethod method = IntegratorMethod::kIdas;
  double relative_tolerance = 1e-6;
  double absolute_tolerance = 1e-9;
  long max_steps = 100000;
  double max_wall_seconds = kDefaultAnalysisWallSeconds;  // <= 0: no limit (not from a file)
};

struct Scene {
  std::string name;
  std::string source_file;  // for messages
  std::vector<Parameter> parameters;
  Effects effects;
  std::variant<LinkageModel, LumpedModel, MultibodyModel, ExternalModel, FmuModel, SpatialModel> model;
  std::vector<Output> outputs;
  TimeGrid time_grid;
  // The parameters the time grid's start_expr / end_expr read (sorted): the
  // grid is computed once, so a study may not vary them.
  std::vector<int> time_grid_parameters_read;
  // Per parameter: for one written as `expr`, its expression, reading only
  // parameters without one (those it names through others are inlined),
  // and its value_si is its value at the defaults; null for a value. Every
  // Number and response that names such a parameter holds its expression
  // instead, so nothing reads its slot of a parameter vector, and a design
  // variable or a load case cannot set it. Empty in a scene built in code.
  std::vector<std::shared_ptr<const Expression>> parameter_expressions;
  // Parameter p's expression (parameter_expressions), or null.
  std::shared_ptr<const Expression> ParameterExpression(int p) const {
    return p >= 0 && p < static_cast<int>(parameter_expressions.size())
               ? parameter_expressions[static_cast<size_t>(p)]
               : nullptr;
  }
  IntegratorSettings integrator;

  int FindParameter(const std::string& name) const;  // -1 if absent
  int FindOutput(const std::string& name) const;     // -1 if absent
  std::vector<double> DefaultParameterValues() const;  // SI
};

}  // namespace mbopt::spec
