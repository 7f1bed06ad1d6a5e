#include "worker/spatial/euler_angles.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace mbopt::spatial {
namespace {

// Below this |sin| (or |cos|) of the middle angle the first and third axes
// coincide to round-off and the split between a1 and a3 is arbitrary.
constexpr double kGimbalLock = 1e-12;

Eigen::Vector3d UnitAxis(int axis) { return Eigen::Vector3d::Unit(axis); }

}  // namespace

Eigen::Matrix3d RotationOfEulerAngles(const EulerSequence& sequence, const Eigen::Vector3d& angles_rad) {
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  for (int k = 0; k < 3; ++k) r = r * Eigen::AngleAxisd(angles_rad[k], UnitAxis(sequence[static_cast<size_t>(k)])).toRotationMatrix();
  return r;
}

Eigen::Vector3d EulerAnglesOf(const EulerSequence& sequence, const Eigen::Matrix3d& r) {
  const int i = sequence[0], j = sequence[1];
  const bool proper = sequence[2] == i;
  const int k = proper ? 3 - i - j : sequence[2];
  // +1 for the cyclic orders (x y z, y z x, z x y), -1 for the others.
  const double s = (j - i + 3) % 3 == 1 ? 1.0 : -1.0;
  Eigen::Vector3d a;
  if (!proper) {
    // R(i,k) = s sin a2; R(j,k) = -s sin a1 cos a2; R(k,k) = cos a1 cos a2;
    // R(i,j) = -s cos a2 sin a3; R(i,i) = cos a2 cos a3.
    a[1] = std::asin(std::clamp(s * r(i, k), -1.0, 1.0));
    if (std::abs(std::cos(a[1])) > kGimbalLock) {
      a[0] = std::atan2(-s * r(j, k), r(k, k));
      a[2] = std::atan2(-s * r(i, j), r(i, i));
    } else {
      a[0] = std::atan2(s * r(k, j), r(j, j));
      a[2] = 0.0;
    }
    return a;
  }
  // R(i,i) = cos a2; R(j,i) = sin a1 sin a2; R(k,i) = -s cos a1 sin a2;
  // R(i,j) = sin a2 sin a3; R(i,k) = s sin a2 cos a3.
  a[1] = std::acos(std::clamp(r(i, i), -1.0, 1.0));
  if (std::abs(std::sin(a[1])) > kGimbalLock) {
    a[0] = std::atan2(r(j, i), -s * r(k, i));
    a[2] = std::atan2(r(i, j), s * r(i, k));
  } else {
    // R = R_i(a1) R_j(0 or pi): R(j,j) = cos a1, R(j,k) = -s sin a1 cos a2.
    a[0] = std::atan2(-s * r(j, k) * (r(i, i) < 0.0 ? -1.0 : 1.0), r(j, j));
    a[2] = 0.0;
  }
  return a;
}

}  // namespace mbopt::spatial
