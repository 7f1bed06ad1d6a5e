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

}  // namespace mbopt::oracle
