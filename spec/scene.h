// A scene as domain types: what spec/io makes of a .scene.textproto after
// validation, free of protobuf. Names were checked and resolved to indices;
// numbers are SI. A Number may still be bound to a parameter: the engine
// resolves parameters per analysis, so one Scene serves every design point.
// Field meanings are documented in proto/mbopt/v1/scene.proto.
#pragma once

#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace mbopt::spec {

// A value in SI units: literal, or the value of parameter `param`.
struct Number {
  double value = 0.0;  // used when param < 0
  int param = -1;      // index into Scene::parameters
  double Resolve(const std::vector<double>& parameter_values_si) const {
    return param >= 0 ? parameter_values_si[static_cast<size_t>(param)] : value;
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
struct LinkageModel {
  std::vector<Joint> joints;
  std::vector<Link> links;
  Driver driver;
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

// ---- outputs
enum class Axis { kX, kY };
struct PointPositionOutput { int link = -1; int point = -1; int joint = -1; Axis axis = Axis::kX; };  // link point, or joint if joint >= 0
struct LinkRotationOutput { int link = -1; };
struct ElementDeflectionOutput { int element = -1; };
struct BodyAccelerationOutput { int body = -1; Vec2 offset_m; Axis axis = Axis::kY; };
struct BendingStressOutput { int link = -1; };
struct DriveTorqueOutput {};
struct MassOutput {};

struct Output {
  std::string name;
  std::variant<PointPositionOutput, LinkRotationOutput, ElementDeflectionOutput,
               BodyAccelerationOutput, BendingStressOutput, DriveTorqueOutput, MassOutput>
      kind;
};

struct TimeGrid {
  double start_s = 0.0, end_s = 0.0;
  int points = 1;  // 1: only end_s
  // The instants: `points` equally spaced from start_s to end_s inclusive
  // (only end_s when points == 1).
  std::vector<double> Instants() const;
};

struct IntegratorSettings {
  double relative_tolerance = 1e-6;
  double absolute_tolerance = 1e-9;
  long max_steps = 100000;
  double max_wall_seconds = 0.0;  // 0: no limit
};

struct Scene {
  std::string name;
  std::string source_file;  // for messages
  std::vector<Parameter> parameters;
  Effects effects;
  std::variant<LinkageModel, LumpedModel> model;
  std::vector<Output> outputs;
  TimeGrid time_grid;
  IntegratorSettings integrator;

  int FindParameter(const std::string& name) const;  // -1 if absent
  int FindOutput(const std::string& name) const;     // -1 if absent
  std::vector<double> DefaultParameterValues() const;  // SI
};

}  // namespace mbopt::spec
