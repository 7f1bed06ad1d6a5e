#include "worker/spatial/euler_parameters.h"

#include <Eigen/Geometry>

namespace mbopt::spatial {

Eigen::Matrix3d Skew(const Eigen::Vector3d& u) {
  Eigen::Matrix3d s;
  s << 0.0, -u.z(), u.y(), u.z(), 0.0, -u.x(), -u.y(), u.x(), 0.0;
  return s;
}

Eigen::Matrix3d RotationOf(const Eigen::Vector4d& p) {
  const double e0 = p[0];
  const Eigen::Vector3d e = p.tail<3>();
  return (e0 * e0 - e.dot(e)) * Eigen::Matrix3d::Identity() + 2.0 * e * e.transpose() + 2.0 * e0 * Skew(e);
}

Matrix34d WorldRateMatrix(const Eigen::Vector4d& p) {
  Matrix34d g;
  g.col(0) = -p.tail<3>();
  g.rightCols<3>() = Skew(p.tail<3>()) + p[0] * Eigen::Matrix3d::Identity();
  return g;
}

Matrix34d BodyRateMatrix(const Eigen::Vector4d& p) {
  Matrix34d l;
  l.col(0) = -p.tail<3>();
  l.rightCols<3>() = -Skew(p.tail<3>()) + p[0] * Eigen::Matrix3d::Identity();
  return l;
}

Matrix34d RotatedVectorJacobian(const Eigen::Vector4d& p, const Eigen::Vector3d& s) {
  // A(p) s = (e0^2 - e.e) s + 2 e (e.s) + 2 e0 e x s, differentiated term by term.
  const double e0 = p[0];
  const Eigen::Vector3d e = p.tail<3>();
  Matrix34d j;
  j.col(0) = 2.0 * e0 * s + 2.0 * e.cross(s);
  j.rightCols<3>() = -2.0 * s * e.transpose() + 2.0 * e.dot(s) * Eigen::Matrix3d::Identity() +
                     2.0 * e * s.transpose() - 2.0 * e0 * Skew(s);
  return j;
}

Eigen::Vector4d EulerParametersOf(const Eigen::Matrix3d& rotation) {
  Eigen::Quaterniond quaternion(rotation);
  quaternion.normalize();
  Eigen::Vector4d p(quaternion.w(), quaternion.x(), quaternion.y(), quaternion.z());
  return p[0] < 0.0 ? Eigen::Vector4d(-p) : p;
}

Eigen::Vector4d EulerParameterRate(const Eigen::Vector4d& p, const Eigen::Vector3d& angular_velocity_rad_per_s) {
  // G G^T = |p|^2 I and G p = 0, so G^T w / 2 is the rate tangent to the
  // unit sphere whose angular velocity is w.
  return 0.5 * WorldRateMatrix(p).transpose() * angular_velocity_rad_per_s;
}

Eigen::Matrix3d AxisAngle(const Eigen::Vector3d& axis, double angle_rad) {
  return Eigen::AngleAxisd(angle_rad, axis.normalized()).toRotationMatrix();
}

}  // namespace mbopt::spatial
