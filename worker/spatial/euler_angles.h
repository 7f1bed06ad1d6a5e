// Euler angles of a stated sequence, as scene files write orientations and
// outputs report them: three successive rotations about the rotated
// (body-fixed) axes, R = R_i(a1) R_j(a2) R_k(a3) with axes i, j, k given as
// 0 (x), 1 (y), 2 (z). Tait-Bryan sequences have three different axes
// (i, j, k), proper Euler sequences repeat the first (i, j, i).
#pragma once

#include <array>

#include <Eigen/Dense>

namespace mbopt::spatial {

using EulerSequence = std::array<int, 3>;

// The rotation of the three angles (rad).
Eigen::Matrix3d RotationOfEulerAngles(const EulerSequence& sequence, const Eigen::Vector3d& angles_rad);

// The angles of a rotation (proper orthogonal): a1 and a3 in (-pi, pi];
// a2 in [-pi/2, pi/2] (Tait-Bryan) or [0, pi] (proper Euler). At the
// sequence's singular middle angle (+-pi/2, or 0 and pi) only a1 + a3 (or
// a1 - a3) is defined: a3 is then reported as 0.
Eigen::Vector3d EulerAnglesOf(const EulerSequence& sequence, const Eigen::Matrix3d& rotation);

}  // namespace mbopt::spatial
