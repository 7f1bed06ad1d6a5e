// LinkageSystem: a planar linkage (bars joined by pins, one bar driven at
// constant angular velocity about a ground pin) with every Number resolved
// to SI values for one design point: the linkage scene as the multibody
// front end (linkage_front_end.h) reads it. Built from spec::LinkageModel by
// ResolveLinkage, which rejects malformed models (bad indices, non-positive
// lengths or section data) with InvalidArgument; whether the mechanism
// assembles is not decided here (that is a numerical outcome of the
// kinematic analysis).
//
// LinkageState is the motion of the linkage at one instant in the scene's
// own terms, indexed by its joints (pins): what the outputs, the rigid-bar
// bending moments and the floating-frame elastodynamics read.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/statusor.h"
#include "spec/scene.h"

namespace mbopt::multibody {

struct LinkageJoint {
  std::string name;
  Eigen::Vector2d position_m;  // as given: start configuration or its initial guess
  bool ground = false;
};

// A point rigidly carried by a link, in the link frame: origin at joint a,
// x along a->b, y = z x x (counter-clockwise normal).
struct LinkagePoint {
  std::string name;
  Eigen::Vector2d local_m;
};

struct LinkageLink {
  std::string name;
  int joint_a = -1, joint_b = -1;
  double length_m = 0.0;
  bool has_section = false;  // without a section the link is massless
  double area_m2 = 0.0;
  double youngs_modulus_pa = 0.0;
  double density_kg_per_m3 = 0.0;
  int flexible_elements = 0;  // 0: rigid
  bool rotary_inertia = false;
  std::vector<LinkagePoint> points;

  bool both_ground = false;  // both joints on the ground: carries nothing

  double mass_per_length_kg_per_m() const { return density_kg_per_m3 * area_m2; }
  // Solid circular section: I = A^2 / (4 pi).
  double second_moment_m4() const;
  // Bending stress from a bending moment on the solid circular section:
  // sigma = M c / I = 4 sqrt(pi) M / A^1.5 (sign of M kept).
  double StressFromMoment(double moment_n_m) const;
};

struct LinkageDriver {
  int link = -1;
  int pivot_joint = -1;   // a ground joint of `link`
  int driven_joint = -1;  // the other joint of `link`
  double start_angle_rad = 0.0;  // absolute angle of pivot->driven at t = 0
  double angular_velocity_rad_per_s = 0.0;
};

struct LinkageSystem {
  std::vector<LinkageJoint> joints;
  std::vector<LinkageLink> links;
  LinkageDriver driver;
  bool has_gravity = false;
  Eigen::Vector2d gravity_m_per_s2 = Eigen::Vector2d::Zero();
  bool has_structural_damping = false;
  double structural_damping_ratio = 0.0;

  bool AnyFlexible() const;
  // Label for messages: "joint 'B'" / "link 'coupler' (joints A-B)".
  std::string JointLabel(int joint) const;
  std::string LinkLabel(int link) const;
};

// Resolves `linkage` at one design point. `effects` supplies gravity and
// structural damping (only where declared).
absl::StatusOr<LinkageSystem> ResolveLinkage(const spec::LinkageModel& linkage, const spec::Effects& effects,
                                             const std::vector<double>& parameter_values_si);

// The linkage at one instant; indexed by joint (ground joints included).
struct LinkageState {
  double time_s = 0.0;
  std::vector<Eigen::Vector2d> position_m, velocity_m_per_s, acceleration_m_per_s2;

  // Rigid-link quantities from the joint states.
  Eigen::Vector2d LinkVector(const LinkageLink& link) const;  // r_b - r_a
  double LinkAngle(const LinkageLink& link) const;            // rad, atan2
  double LinkAngularVelocity(const LinkageLink& link) const;  // rad/s
  double LinkAngularAcceleration(const LinkageLink& link) const;  // rad/s^2
};

}  // namespace mbopt::multibody
