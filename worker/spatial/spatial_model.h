// A spatial multibody model as the engine computes with it: rigid bodies,
// frames (markers) on them, joints between frames, drivers, translational
// spring-dampers and gravity, every number a plain SI double. Immutable
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

// Tension T = k (L - L0) + c dL/dt between two points, pulling them
// together when positive.
struct SpringDamper {
  std::string name;
  Point a, b;
  double stiffness_n_per_m = 0.0;
  double free_length_m = 0.0;
  double damping_n_s_per_m = 0.0;
};

struct Model {
  std::vector<Body> bodies;
  std::vector<Joint> joints;
  std::vector<Driver> drivers;
  std::vector<SpringDamper> springs;
  std::optional<Eigen::Vector3d> gravity_m_per_s2;  // absent: no gravity computed

  // InvalidArgument naming the body, joint or element and what was expected.
  absl::Status Validate() const;
  std::string BodyName(int body) const;
};

const char* JointKindName(Joint::Kind kind);
// The number of constraint equations of a joint of this kind.
int JointEquationCount(Joint::Kind kind);

}  // namespace mbopt::spatial
