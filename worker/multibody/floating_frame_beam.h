// The floating-frame formulation's beam element (floating_frame.h): a planar
// Euler-Bernoulli element (axial bar + cubic Hermite bending) in its own
// local frame, small displacements only: x along the element, y = z x x. Local degrees of
// freedom, in this order: (u1, w1, theta1, u2, w2, theta2), with u axial and
// w transverse displacements in m and theta rotations in rad. Stiffness in
// N/m (N, N m per unit), consistent mass in kg (kg m, kg m^2). Uniform
// section along the element. Owns nothing; pure functions of the data.
#pragma once

#include <Eigen/Dense>

namespace mbopt::multibody::floating_frame {

struct BeamSection {
  double length_m = 0.0;                    // element length
  double axial_stiffness_n = 0.0;           // E A
  double bending_stiffness_n_m2 = 0.0;      // E I
  double mass_per_length_kg_per_m = 0.0;    // rho A
  double rotary_inertia_kg_m = 0.0;         // rho I (0: no rotary inertia)
};

using BeamMatrix = Eigen::Matrix<double, 6, 6>;

BeamMatrix BeamStiffness(const BeamSection& s);
// Consistent mass: linear shape functions for u, Hermite for w, plus the
// rotary inertia of the section when rotary_inertia_kg_m > 0.
BeamMatrix BeamConsistentMass(const BeamSection& s);
// Geometric stiffness of an axial force (N, tension > 0) acting on the
// bending dofs: the consistent matrix of (N/2) integral w'^2 with the Hermite
// shape functions. Tension stiffens the element, compression softens it (the
// P-delta moment N w); axial dofs are untouched.
BeamMatrix BeamGeometricStiffness(double length_m, double axial_force_n);

}  // namespace mbopt::multibody::floating_frame
