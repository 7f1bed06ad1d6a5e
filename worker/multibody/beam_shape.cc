#include "worker/multibody/beam_shape.h"

#include "worker/multibody/beam_element.h"

namespace mbopt::multibody {

bool AppendBeamInnerPoints(const Mechanism& mechanism, int element, const Eigen::VectorXd& q, int inner_points,
                           std::vector<Eigen::Vector2d>* out) {
  BeamLoads loads;
  // No velocities: the shape needs the rotations only.
  if (!mechanism.BeamEndLoads(element, q, Eigen::VectorXd(), &loads)) return false;
  const BeamElement& e = mechanism.model().beams[static_cast<size_t>(element)];
  const Eigen::Vector2d a = q.segment<2>(3 * static_cast<Eigen::Index>(e.a));
  const Eigen::Vector2d along(loads.chord_cos, loads.chord_sin);
  const Eigen::Vector2d normal(-loads.chord_sin, loads.chord_cos);
  const double l = loads.chord_length_m;
  for (int k = 1; k <= inner_points; ++k) {
    const double xi = static_cast<double>(k) / (inner_points + 1);
    const double w = l * (loads.rotation_a_rad * (xi - 2 * xi * xi + xi * xi * xi) +
                          loads.rotation_b_rad * (xi * xi * xi - xi * xi));
    out->push_back(a + xi * l * along + w * normal);
  }
  return true;
}

}  // namespace mbopt::multibody
