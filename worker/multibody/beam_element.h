// A planar co-rotational Euler-Bernoulli beam element between two nodes
// (Crisfield, Non-linear Finite Element Analysis of Solids and Structures,
// vol. 1, section 7.2; Battini and Pacoste 2002): the element's rigid motion
// is followed exactly by a frame along the chord between its nodes, and in
// that frame the deformation is small and linear,
//
//   u = l - L0                   N  = EA u / L0
//   theta_a = phi_a - beta - a0  Ma = 2 EI / L0 (2 theta_a + theta_b)
//   theta_b = phi_b - beta - b0  Mb = 2 EI / L0 (theta_a + 2 theta_b)
//
// (l, beta: the chord's current length and angle; a0, b0: each node's angle
// to the chord in the undeformed state), plus beta_d times the same loads of
// the local deformation rates (u' = r . x', theta_a' = phi_a' - z . x' / l,
// ...) for stiffness-proportional damping. Large rotations and the axial
// force's effect on bending come from the formulation, not from a
// correction. The nodes are bodies of the mechanism (x, y, phi each); the
// internal forces on (x_a, y_a, phi_a, x_b, y_b, phi_b) are
// f = N r + Ma (e3 - z / l) + Mb (e6 - z / l), r = (-c, -s, 0, c, s, 0),
// z = (s, -c, 0, -s, c, 0), c = cos beta, s = sin beta, and the element
// applies -f to its nodes. The strain energy is
// EA u^2 / (2 L0) + 2 EI / L0 (theta_a^2 + theta_a theta_b + theta_b^2).
#pragma once

#include <string>

#include <Eigen/Dense>

namespace mbopt::multibody {

struct BeamElement {
  std::string name;              // for messages: "link 'coupler' element 3"
  int a = 0, b = 0;              // node bodies
  double length_m = 0.0;         // L0
  double axial_stiffness_n = 0.0;       // EA
  double bending_stiffness_n_m2 = 0.0;  // EI
  double angle_a_rad = 0.0, angle_b_rad = 0.0;  // a0, b0
  // Stiffness-proportional structural damping C = beta K in the element's
  // frame: beta times the local loads of the deformation rates.
  double damping_s = 0.0;  // beta
};

using BeamNodes = Eigen::Matrix<double, 6, 1>;  // (x_a, y_a, phi_a, x_b, y_b, phi_b)

struct BeamLoads {
  double axial_n = 0.0;                      // N, tension positive
  double moment_a_n_m = 0.0, moment_b_n_m = 0.0;  // Ma, Mb on the nodes' side
  double stretch_m = 0.0, rotation_a_rad = 0.0, rotation_b_rad = 0.0;
  double chord_length_m = 0.0, chord_cos = 1.0, chord_sin = 0.0;  // l, cos beta, sin beta
};

// The element's end loads at the nodes' coordinates (and, with `x_dot`,
// their damping part); false if the nodes coincide (no chord).
bool EvaluateBeam(const BeamElement& e, const BeamNodes& x, const BeamNodes* x_dot, BeamLoads* loads);
// The internal forces f (the element applies -f to its nodes), from the
// loads and chord EvaluateBeam found.
BeamNodes BeamInternalForces(const BeamLoads& loads);
double BeamStrainEnergy(const BeamElement& e, const BeamLoads& loads);

}  // namespace mbopt::multibody
