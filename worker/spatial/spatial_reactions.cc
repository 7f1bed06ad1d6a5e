#include "worker/spatial/spatial_reactions.h"

#include <cmath>

#include "worker/spatial/euler_parameters.h"

namespace mbopt::spatial {

JointReaction JointReactionOf(const SpatialSystem& system, int joint, double t, const Eigen::VectorXd& q,
                              const Eigen::VectorXd& lambda) {
  const Model& model = system.model();
  const Joint& j = model.joints[static_cast<size_t>(joint)];
  const bool on_b = j.b.body != kGround;
  const int body = on_b ? j.b.body : j.a.body;
  Eigen::MatrixXd phi_q;
  system.ConstraintJacobian(t, q, &phi_q);
  const int first = system.first_row_of_joint(joint), rows = JointEquationCount(j.kind);
  constexpr int kBlock = SpatialSystem::kCoordinatesPerBody;
  const Eigen::Matrix<double, kBlock, 1> generalized =
      -phi_q.block(first, kBlock * body, rows, kBlock).transpose() * lambda.segment(first, rows);
  const Eigen::Vector4d p = q.segment<4>(kBlock * body + 3);
  JointReaction r;
  r.force_n = generalized.head<3>();
  const Eigen::Vector3d torque = WorldRateMatrix(p) * generalized.tail<4>() / (2.0 * p.squaredNorm());
  // From the centre of mass to frame b's origin.
  const Eigen::Vector3d arm = system.PointPosition(Point{j.b.body, j.b.position_m}, q) - q.segment<3>(kBlock * body);
  r.moment_n_m = torque - arm.cross(r.force_n);
  if (!on_b) {
    r.force_n = -r.force_n;
    r.moment_n_m = -r.moment_n_m;
  }
  return r;
}

}  // namespace mbopt::spatial
