#include "worker/multibody/flexible_link.h"

#include <cmath>

namespace mbopt::multibody {

FlexibleLinkNodes AddFlexibleLink(const FlexibleLinkSpec& link, Model* model) {
  FlexibleLinkNodes nodes;
  nodes.first_node = static_cast<int>(model->bodies.size());
  nodes.elements = link.elements;
  nodes.first_element = static_cast<int>(model->beams.size());
  const int n = link.elements;
  const double element_length = link.length_m / n;
  const double element_mass = link.mass_per_length_kg_per_m * element_length;
  const Eigen::Vector2d direction(std::cos(link.angle_rad), std::sin(link.angle_rad));
  for (int k = 0; k <= n; ++k) {
    const double ends = (k == 0 || k == n) ? 1.0 : 2.0;  // elements meeting at the node
    Body node;
    node.name = link.name + "#" + std::to_string(k);
    node.mass_kg = ends * element_mass / 2.0;
    node.inertia_kg_m2 = ends * (element_mass * element_length * element_length / 78.0 +
                                 link.rotary_inertia_per_length_kg_m * element_length / 2.0);
    node.position_m = link.start_m + k * element_length * direction;
    node.angle_rad = link.angle_rad;
    model->bodies.push_back(node);
  }
  for (int k = 0; k < n; ++k) {
    BeamElement e;
    e.name = "link '" + link.name + "' element " + std::to_string(k + 1);
    e.a = nodes.node(k);
    e.b = nodes.node(k + 1);
    e.length_m = element_length;
    e.axial_stiffness_n = link.axial_stiffness_n;
    e.bending_stiffness_n_m2 = link.bending_stiffness_n_m2;
    e.damping_s = link.damping_s;
    model->beams.push_back(e);
  }
  return nodes;
}

void SetRigidLinkVelocityColumns(const Eigen::VectorXd& q0, int first_node, int elements, int column,
                                 Eigen::MatrixXd* velocity_basis) {
  Eigen::MatrixXd& basis = *velocity_basis;
  for (int k = 0; k <= elements; ++k) {
    const int node = first_node + k;
    const Eigen::Vector2d arm = q0.segment<2>(3 * node) - q0.segment<2>(3 * first_node);
    basis(3 * node, column) = 1.0;
    basis(3 * node + 1, column + 1) = 1.0;
    basis(3 * node, column + 2) = -arm.y();
    basis(3 * node + 1, column + 2) = arm.x();
    basis(3 * node + 2, column + 2) = 1.0;
  }
}

}  // namespace mbopt::multibody
