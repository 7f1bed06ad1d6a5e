// The spatial mechanisms that Simbody (the C++17 program
// mbopt_simbody_spatial_oracle) and mbopt both simulate, as plain numbers
// shared by the two: no Simbody and no mbopt types here.
//
// Spatial double pendulum: two bodies on spherical joints under gravity
// (0, 0, -g). Each body's frame is at its centre of mass; its inboard joint
// is at (0, 0, +half_length) and the upper body's outboard joint at
// (0, 0, -half_length), in body axes. Initial orientations (body to world)
// are rotations by angle_rad about axis. Released at rest, or (spinning)
// with both bodies turning together about the shoulder at
// angular_velocity (world axes): the velocities of one rigid body. Values,
// per instant: the two
// centres of mass (x, y, z, world, m) and the two rotation matrices (row by
// row), 24 numbers.
#pragma once

namespace mbopt::oracle {

struct SpatialDoublePendulum {
  double g = 9.81;
  double mass_kg[2] = {1.0, 0.5};
  double inertia_kg_m2[2][3] = {{0.09, 0.085, 0.01}, {0.03, 0.027, 0.004}};  // principal, body axes
  double half_length_m[2] = {0.5, 0.35};
  double axis[2][3] = {{1.0, 0.3, 0.0}, {0.2, 1.0, 0.5}};
  double angle_rad[2] = {0.6, -0.9};
  double angular_velocity_rad_per_s[3] = {0.5, -1.0, 2.0};
};

// A chain hung on springs, for static equilibrium: two bodies under gravity
// (0, 0, -g), the upper hinged to ground at the origin about world x, the
// lower hinged to the upper about world y (axes of the start pose, where
// both hang straight down: body frames at their centres of mass, axes
// world's; each body's hinge at (0, 0, +half_length) in its axes, the
// upper's lower hinge at (0, 0, -half_length)). Each body is pulled by a
// spring from a ground anchor (world) to a point of the body (body axes).
// Simbody brings it to rest with a damper on each hinge; values: the two
// centres of mass and rotation matrices, as the double pendulum's.
struct SpatialHungChain {
  double g = 9.81;
  double mass_kg[2] = {1.2, 0.8};
  double inertia_kg_m2[2][3] = {{0.05, 0.04, 0.02}, {0.03, 0.025, 0.01}};  // principal, body axes
  double half_length_m[2] = {0.3, 0.3};
  double anchor_m[2][3] = {{0.4, 0.3, -0.2}, {-0.3, 0.5, -1.0}};        // world
  double attachment_m[2][3] = {{0.0, 0.05, -0.2}, {0.02, 0.0, -0.3}};  // body axes
  double stiffness_n_per_m[2] = {60.0, 40.0};
  double free_length_m[2] = {0.1, 0.2};
  double hinge_damping_n_m_s_per_rad[2] = {4.0, 1.0};  // Simbody's only
};

// A body hung by a bushing (Simbody's Force::LinearBushing) from a frame F
// fixed in ground, under gravity (0, 0, -g), and released turned far from
// the bushing's rest. F's origin is at ground_frame_m (world), its axes
// the world's turned by ground_angle_rad about ground_axis; the bushing's
// frame M on the body is at body_frame_m from the centre of mass (body
// axes) with the body's axes. At the start M is turned from F by
// turn_angle_rad about turn_axis and displaced by displacement_m (both in
// F's axes); the body moves at velocity_m_per_s (its centre of mass) and
// angular_velocity_rad_per_s (world axes). Stiffnesses and dampings as
// Simbody orders them: about M's x-y-z angles in F, then along F's axes.
// Values per instant: the centre of mass and the rotation matrix (row by
// row), 12 numbers.
struct SpatialBushingBody {
  double g = 9.81;
  double mass_kg = 1.5;
  double inertia_kg_m2[3] = {0.08, 0.05, 0.03};  // principal, body axes
  double ground_frame_m[3] = {0.1, -0.2, 0.3};
  double ground_axis[3] = {0.3, -1.0, 0.4};
  double ground_angle_rad = 0.5;
  double body_frame_m[3] = {0.02, -0.03, 0.15};
  double stiffness[6] = {3.0, 5.0, 2.0, 400.0, 250.0, 600.0};  // N m/rad, then N/m
  double damping[6] = {0.02, 0.05, 0.01, 2.0, 1.0, 3.0};       // N m s/rad, then N s/m
  double turn_axis[3] = {1.0, 0.8, -0.6};
  double turn_angle_rad = 1.1;
  double displacement_m[3] = {0.03, -0.02, 0.05};
  double velocity_m_per_s[3] = {0.1, 0.2, -0.1};
  double angular_velocity_rad_per_s[3] = {1.5, -2.0, 1.0};
};

}  // namespace mbopt::oracle
