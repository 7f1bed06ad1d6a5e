// A planar multibody model as the engine computes with it: rigid bodies in
// absolute coordinates (x, y of the centre of mass and the angle phi per
// body), joints between markers, drivers, force elements and gravity, every
// number a plain SI double (a scene's parameters are resolved before this is
// built; see docs/physics.md, "General planar multibody"). Immutable during an
// analysis: per-analysis state lives in the solvers (the model/data split).
//
// Conventions:
//  - Ground is body kGround (-1); its markers are fixed points in world axes.
//  - A marker's position is in its body's axes, relative to the centre of mass.
//  - Revolute joint coordinate: phi_b - phi_a (rad). Prismatic joint
//    coordinate: the displacement of marker b from marker a along the axis
//    fixed in body a (m); the relative angle is held at its initial value.
//    Fixed joint: markers coincide and the relative angle is held.
//    Point-on-line joint (a pin in a slot): marker b stays on the line through
//    marker a along the axis fixed in body a; rotation is free. Its
//    coordinate is the prismatic one.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/status.h"
#include "worker/multibody/beam_element.h"

namespace mbopt::multibody {

inline constexpr int kGround = -1;

struct Body {
  std::string name;
  double mass_kg = 0.0;
  double inertia_kg_m2 = 0.0;  // about the centre of mass
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();  // initial guess of the centre of mass
  double angle_rad = 0.0;                                // initial guess
};

// A point of a body (or of ground): the body's index and the point in its
// axes (relative to the centre of mass; world axes for ground).
struct Point {
  int body = kGround;
  Eigen::Vector2d local_m = Eigen::Vector2d::Zero();
  std::string name;  // for messages
  int input = -1;    // >= 0: the moving input point Model::inputs[input] (body is ground)
};

enum class JointKind { kRevolute, kPrismatic, kFixed, kPointOnLine };

struct Joint {
  std::string name;
  JointKind kind = JointKind::kRevolute;
  Point a, b;
  double axis_angle_rad = 0.0;   // prismatic, point on line: the axis in body a's axes
  // Initial conditions of the joint coordinate (held in assembly when given).
  std::optional<double> initial_value;
  std::optional<double> initial_rate;
};

// A natural cubic spline through (x_k, y_k), x strictly increasing: C2, so a
// tabulated driver has a continuous acceleration. Outside [x_0, x_n] it is
// not defined (Evaluate returns false).
class CubicSpline {
 public:
  CubicSpline() = default;
  CubicSpline(std::vector<double> x, std::vector<double> y);
  bool Evaluate(double x, double* y, double* dy, double* d2y) const;
  bool empty() const { return x_.empty(); }
  double front() const { return x_.front(); }
  double back() const { return x_.back(); }

 private:
  std::vector<double> x_, y_, second_;  // second derivatives at the knots
};

// Piecewise-linear y(x) through a table, x strictly increasing; Evaluate
// returns false outside the table (no extrapolation: a force curve measured
// over a range says nothing beyond it).
struct LinearTable {
  std::vector<double> x, y;
  bool Evaluate(double at, double* value) const;
  // y at any x: inside the table as Evaluate, outside along the end
  // segment's line (only for an integrator's trial steps across the table's
  // end, see ConstrainedSystem::ContinuePastBounds, never for a result).
  double Continued(double at) const;
  // dy/dx of Continued at `at`: the slope of the segment that holds it (at
  // a breakpoint, the segment above it, as Evaluate picks).
  double Slope(double at) const;
  bool empty() const { return x.empty(); }
};

// A prescribed joint coordinate q(t) with its first two derivatives.
struct Profile {
  enum class Kind { kConstantRate, kPolynomial, kHarmonic, kTabulated } kind = Kind::kConstantRate;
  CubicSpline table;                  // kTabulated: q through (t_k, q_k)
  double start = 0.0;                 // kConstantRate, kHarmonic: q0
  double rate = 0.0;                  // kConstantRate: dq/dt
  std::vector<double> coefficients;   // kPolynomial: c0 + c1 t + c2 t^2 + ...
  double amplitude = 0.0;             // kHarmonic: q0 + A sin(omega t + phase)
  double angular_frequency_rad_per_s = 0.0;
  double phase_rad = 0.0;

  struct Value {
    double q = 0.0, q_dot = 0.0, q_ddot = 0.0;
  };
  Value At(double t_s) const;
};

struct Driver {
  int joint = -1;  // a revolute or prismatic joint
  Profile profile;
};

// Tension T = k (L - L0) + c dL/dt + actuator, pulling the two points
// together when positive. With a deflection curve, its force at L - L0
// replaces k (L - L0); with a velocity curve, its force at dL/dt replaces
// c dL/dt.
struct SpringDamper {
  std::string name;
  Point a, b;
  double free_length_m = 0.0;
  double stiffness_n_per_m = 0.0;
  double damping_n_s_per_m = 0.0;
  double actuator_force_n = 0.0;
  LinearTable deflection_curve;  // force (N) against L - L0 (m)
  LinearTable velocity_curve;    // force (N) against dL/dt (m/s)
};

// Torque on body b of a revolute joint: -k (theta - theta0) - c dtheta/dt
// (theta: the joint coordinate), the opposite on body a.
struct RotationalSpringDamper {
  std::string name;
  int joint = -1;
  double stiffness_n_m_per_rad = 0.0;
  double damping_n_m_s_per_rad = 0.0;
  double free_angle_rad = 0.0;
};

// A force or torque varies in time when it has a profile: its value is then
// the constant one times the profile's q(t) (a harmonic or tabulated
// factor).
struct PointForce {
  Point at;
  Eigen::Vector2d force_n = Eigen::Vector2d::Zero();  // world axes
  std::optional<Profile> factor;
};

struct BodyTorque {
  int body = 0;
  double torque_n_m = 0.0;  // counter-clockwise positive
  std::optional<Profile> factor;
};

// A point of ground that moves in time along a fixed direction (a road
// profile under a wheel, a shaker's table): position + direction * d(t).
// Springs and forces may attach to it; joints may not (it is not a body).
struct InputPoint {
  std::string name;
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  Eigen::Vector2d direction = Eigen::Vector2d(0.0, 1.0);  // unit
  Profile displacement;
};

struct Model {
  std::vector<InputPoint> inputs;
  std::vector<Body> bodies;
  std::vector<Joint> joints;
  std::vector<Driver> drivers;
  std::vector<SpringDamper> springs;
  std::vector<RotationalSpringDamper> rotational_springs;
  std::vector<PointForce> point_forces;
  std::vector<BodyTorque> torques;
  // Co-rotational beam elements between node bodies: the flexible links.
  std::vector<BeamElement> beams;
  std::optional<Eigen::Vector2d> gravity_m_per_s2;  // absent: no gravity computed

  // InvalidArgument naming the body, joint or element and what was expected.
  absl::Status Validate() const;
  std::string BodyName(int body) const;
};

}  // namespace mbopt::multibody
