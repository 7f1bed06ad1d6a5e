// A spatial multibody model as the engine computes with it: rigid bodies,
// frames (markers) on them, joints between frames, drivers, translational
// spring-dampers, gravity and the force elements of spatial_force_elements.h,
// every number a plain SI double. Immutable
// during an analysis (the model/data split of the planar kernel,
// worker/multibody/model.h); the equations live in SpatialSystem.
//
// Conventions:
//  - Ground is body kGround (-1); its frames are fixed in world axes.
//  - A body's reference frame is at its centre of mass; its orientation is
//    the rotation matrix from body axes to world axes (columns: the body's
//    x, y, z axes in world axes).
//  - A frame's position and axes are in its body's axes, relative to the
//    centre of mass (ground: world).
//  - Joints constrain frame b relative to frame a; the joint axis is frame
//    a's z axis. Rotation coordinate (revolute, cylindrical): the angle from
//    frame a's x axis to frame b's x axis about frame a's z axis (rad).
//    Translation coordinate (prismatic, cylindrical): the displacement of
//    frame b's origin from frame a's along frame a's z axis (m).
//    Universal joint: the cross's two axes are frame a's x axis and frame
//    b's y axis. Fixed, prismatic and the angular part of the others hold
//    the orientation the frames assemble in, so they are written with
//    frames whose axes coincide in the initial pose (docs/physics.md,
//    "Spatial scenes", lists every joint's equations).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/status.h"
#include "worker/multibody/model.h"

namespace mbopt::spatial {

inline constexpr int kGround = -1;

struct Body {
  std::string name;
  double mass_kg = 1.0;
  // About the centre of mass, in body axes: symmetric positive definite and
  // physically possible (each principal moment at most the sum of the others).
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Identity();
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();          // centre of mass, world
  Eigen::Matrix3d orientation = Eigen::Matrix3d::Identity();      // body to world, proper orthogonal
  Eigen::Vector3d velocity_m_per_s = Eigen::Vector3d::Zero();     // of the centre of mass, world
  Eigen::Vector3d angular_velocity_rad_per_s = Eigen::Vector3d::Zero();  // world axes
};

// A point fixed in a body (or ground).
struct Point {
  int body = kGround;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // body axes, from the centre of mass
};

// A frame (marker) fixed in a body: origin and axes in body axes.
struct Frame {
  int body = kGround;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  // columns x, y, z; proper orthogonal
};

struct Joint {
  enum class Kind {
    kSpherical,     // origins coincide (3 equations)
    kRevolute,      // origins coincide, z axes stay aligned (5)
    kUniversal,     // origins coincide, a's x axis stays normal to b's y axis (4)
    kFixed,         // origins coincide, axes held (6)
    kPrismatic,     // b's origin on a's z axis, axes held (5)
    kCylindrical,   // b's origin on a's z axis, z axes stay aligned (4)
    kPlanar,        // b's origin in a's x-y plane, z axes stay aligned (3)
    kPointOnLine,   // b's origin on a's z axis (2)
    kPointOnPlane,  // b's origin in a's x-y plane (1)
  };
  std::string name;
  Kind kind = Kind::kSpherical;
  Frame a, b;
};

// A joint coordinate as a function of time (the planar drivers' profiles):
// the rotation of a revolute or cylindrical joint (rad), or with `slide` the
// translation of a prismatic or cylindrical joint (m).
struct Driver {
  int joint = -1;
  multibody::Profile profile;
  bool slide = false;
};

// Tension T = k (L - L0) + c dL/dt + actuator between two points, pulling
// them together when positive. With a deflection curve, its force at
// L - L0 replaces k (L - L0); with a velocity curve, its force at dL/dt
// replaces c dL/dt (multibody::SpringDamper's curves).
struct SpringDamper {
  std::string name;
  Point a, b;
  double stiffness_n_per_m = 0.0;
  double free_length_m = 0.0;
  double damping_n_s_per_m = 0.0;
  double actuator_force_n = 0.0;
  multibody::LinearTable deflection_curve;  // force (N) against L - L0 (m)
  multibody::LinearTable velocity_curve;    // force (N) against dL/dt (m/s)
};

// A force at a body point, constant or times a time factor's q(t); its
// components in world axes or in its body's axes (turning with the body).
struct PointForce {
  std::string name;
  Point at;
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  bool body_axes = false;
  std::optional<multibody::Profile> factor;
};

// A couple on a body, as a point force.
struct BodyTorque {
  std::string name;
  int body = 0;
  Eigen::Vector3d torque_n_m = Eigen::Vector3d::Zero();
  bool body_axes = false;
  std::optional<multibody::Profile> factor;
};

// Torque -k (theta - theta0) - c dtheta/dt on body b of a revolute or
// cylindrical joint about its axis (the opposite on body a), theta the
// joint's angle counting whole turns along the analysis
// (spatial_force_elements.h, SpringAngles).
struct RotationalSpringDamper {
  std::string name;
  int joint = -1;
  double stiffness_n_m_per_rad = 0.0;
  double damping_n_m_s_per_rad = 0.0;
  double free_angle_rad = 0.0;
};

// Six stiffnesses and dampings between frame a and frame b, in frame a's
// axes (spatial_force_elements.h states the measures of displacement and
// rotation).
struct Bushing {
  std::string name;
  Frame a, b;
  Eigen::Vector3d stiffness_n_per_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d damping_n_s_per_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d rotational_stiffness_n_m_per_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d rotational_damping_n_m_s_per_rad = Eigen::Vector3d::Zero();
};

struct Model {
  std::vector<Body> bodies;
  std::vector<Joint> joints;
  std::vector<Driver> drivers;
  std::vector<SpringDamper> springs;
  std::optional<Eigen::Vector3d> gravity_m_per_s2;  // absent: no gravity computed
  std::vector<PointForce> point_forces;
  std::vector<BodyTorque> torques;
  std::vector<RotationalSpringDamper> rotational_springs;
  std::vector<Bushing> bushings;

  // InvalidArgument naming the body, joint or element and what was expected.
  absl::Status Validate() const;
  std::string BodyName(int body) const;
};

const char* JointKindName(Joint::Kind kind);
// The number of constraint equations of a joint of this kind.
int JointEquationCount(Joint::Kind kind);

}  // namespace mbopt::spatial
