// A flexible link as the engine builds it: a straight, uniform beam of
// `elements` co-rotational beam elements (beam_element.h) whose elements + 1
// nodes are bodies of the model, named "LINK#k", along the link from end a
// (node 0) to end b (node `elements`). Masses are lumped at the nodes by the
// HRZ rule (Hinton, Rock and Zienkiewicz 1976: the diagonal of the consistent
// mass matrix scaled to the element's mass): m_e / 2 and a rotary inertia
// m_e L_e^2 / 78 per element end, so the mass matrix stays constant and
// diagonal; the section's own rotary inertia rho I L_e / 2 per element end
// is added when given.
#pragma once

#include <string>

#include <Eigen/Dense>

#include "worker/multibody/model.h"

namespace mbopt::multibody {

struct FlexibleLinkSpec {
  std::string name;
  Eigen::Vector2d start_m = Eigen::Vector2d::Zero();  // end a in the start configuration
  double angle_rad = 0.0;                             // from a to b in the start configuration
  double length_m = 0.0;
  double axial_stiffness_n = 0.0;       // EA
  double bending_stiffness_n_m2 = 0.0;  // EI
  double mass_per_length_kg_per_m = 0.0;
  // The sections' own rotary inertia rho I per length, added at the nodes
  // (0: left out, as for slender links).
  double rotary_inertia_per_length_kg_m = 0.0;
  double damping_s = 0.0;  // stiffness-proportional beta of every element
  int elements = 4;
};

// The node bodies and elements of `link` added to `model`; the link's node
// k is body first_node + k.
struct FlexibleLinkNodes {
  int first_node = 0;
  int elements = 0;
  int first_element = 0;  // index in Model::beams
  int node(int k) const { return first_node + k; }
  int end_a() const { return first_node; }
  int end_b() const { return first_node + elements; }
};
FlexibleLinkNodes AddFlexibleLink(const FlexibleLinkSpec& link, Model* model);

// Three columns of an assembly's velocity basis (AssemblyOptions::
// velocity_basis) from `column` on: the rigid motions (x, y, rotation about
// node 0) of the link whose `elements` + 1 node bodies start at body
// `first_node`, at the coordinates `q0`. Starting a flexible link with a
// rigid-body velocity keeps its elastic modes at rest.
void SetRigidLinkVelocityColumns(const Eigen::VectorXd& q0, int first_node, int elements, int column,
                                 Eigen::MatrixXd* velocity_basis);

}  // namespace mbopt::multibody
