// Joint reactions and driver efforts of a spatial system from its Lagrange
// multipliers. With M a + Phi_q^T lambda = Q, a joint's rows exert the
// generalized force -Phi_q(rows)^T lambda(rows) on each of its bodies: on
// the centre of mass its first three entries are the force (world axes),
// and its Euler-parameter entries g give the torque n = G(p) g / (2 |p|^2)
// (world axes; the part of g along p is the normalization row's).
#pragma once

#include <Eigen/Dense>

#include "worker/spatial/spatial_system.h"

namespace mbopt::spatial {

// The force (N) and the moment about frame b's origin (N m), world axes,
// that joint `joint` exerts on frame b's body; with frame b on ground,
// minus those it exerts on frame a's body (the reaction on ground).
struct JointReaction {
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment_n_m = Eigen::Vector3d::Zero();
};
JointReaction JointReactionOf(const SpatialSystem& system, int joint, double t, const Eigen::VectorXd& q,
                              const Eigen::VectorXd& lambda);

}  // namespace mbopt::spatial
