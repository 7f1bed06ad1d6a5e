// Orientation by Euler parameters (unit quaternions) p = (e0, e1, e2, e3):
// the rotation from body axes to world axes, the matrices that map dp/dt to
// angular velocity, and the exact derivatives of a rotated vector with
// respect to p. Every function is defined for any p, not only unit ones:
// A(p) below is the homogeneous quadratic form that equals the rotation
// matrix on |p| = 1, so the constraint equations built from it have exact
// Jacobians off the unit sphere too (Newton's trial points and the
// integrator's predictions leave it; docs/physics.md, "Spatial scenes").
#pragma once

#include <Eigen/Dense>

namespace mbopt::spatial {

using Matrix34d = Eigen::Matrix<double, 3, 4>;

// [u]x: Skew(u) w = u x w.
Eigen::Matrix3d Skew(const Eigen::Vector3d& u);

// A(p) = (e0^2 - e.e) I + 2 e e^T + 2 e0 [e]x: body axes to world axes.
Eigen::Matrix3d RotationOf(const Eigen::Vector4d& p);

// G(p) = [-e, [e]x + e0 I]: angular velocity in world axes = 2 G(p) dp/dt.
Matrix34d WorldRateMatrix(const Eigen::Vector4d& p);

// L(p) = [-e, -[e]x + e0 I]: angular velocity in body axes = 2 L(p) dp/dt.
Matrix34d BodyRateMatrix(const Eigen::Vector4d& p);

// d(A(p) s)/dp (3 x 4), exact for any p. A is quadratic in p, so along a
// path d2(A s)/dt2 = (d(A s)/dp) p'' + 2 A(p') s.
Matrix34d RotatedVectorJacobian(const Eigen::Vector4d& p, const Eigen::Vector3d& s);

// The unit Euler parameters of a rotation matrix (proper orthogonal), with
// e0 >= 0.
Eigen::Vector4d EulerParametersOf(const Eigen::Matrix3d& rotation);

// dp/dt of unit parameters p for an angular velocity in world axes.
Eigen::Vector4d EulerParameterRate(const Eigen::Vector4d& p, const Eigen::Vector3d& angular_velocity_rad_per_s);

// The rotation by `angle_rad` about `axis` (any non-zero length).
Eigen::Matrix3d AxisAngle(const Eigen::Vector3d& axis, double angle_rad);

}  // namespace mbopt::spatial
