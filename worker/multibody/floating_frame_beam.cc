#include "worker/multibody/floating_frame_beam.h"

namespace mbopt::multibody::floating_frame {

namespace {
// Local index of the bending dofs (w1, theta1, w2, theta2) and axial (u1, u2).
constexpr int kBend[4] = {1, 2, 4, 5};
constexpr int kAxial[2] = {0, 3};
}  // namespace

BeamMatrix BeamStiffness(const BeamSection& s) {
  const double h = s.length_m;
  BeamMatrix k = BeamMatrix::Zero();
  const double ka = s.axial_stiffness_n / h;
  const double a[2][2] = {{ka, -ka}, {-ka, ka}};
  const double c = s.bending_stiffness_n_m2 / (h * h * h);
  const double b[4][4] = {{12 * c, 6 * h * c, -12 * c, 6 * h * c},
                          {6 * h * c, 4 * h * h * c, -6 * h * c, 2 * h * h * c},
                          {-12 * c, -6 * h * c, 12 * c, -6 * h * c},
                          {6 * h * c, 2 * h * h * c, -6 * h * c, 4 * h * h * c}};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) k(kAxial[i], kAxial[j]) = a[i][j];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) k(kBend[i], kBend[j]) = b[i][j];
  return k;
}

BeamMatrix BeamConsistentMass(const BeamSection& s) {
  const double h = s.length_m;
  BeamMatrix m = BeamMatrix::Zero();
  const double ma = s.mass_per_length_kg_per_m * h / 6.0;
  const double a[2][2] = {{2 * ma, ma}, {ma, 2 * ma}};
  const double c = s.mass_per_length_kg_per_m * h / 420.0;
  const double b[4][4] = {{156 * c, 22 * h * c, 54 * c, -13 * h * c},
                          {22 * h * c, 4 * h * h * c, 13 * h * c, -3 * h * h * c},
                          {54 * c, 13 * h * c, 156 * c, -22 * h * c},
                          {-13 * h * c, -3 * h * h * c, -22 * h * c, 4 * h * h * c}};
  // Rotary inertia of the section (rho I): theta = w' with Hermite slopes.
  const double r = s.rotary_inertia_kg_m / (30.0 * h);
  const double ri[4][4] = {{36 * r, 3 * h * r, -36 * r, 3 * h * r},
                           {3 * h * r, 4 * h * h * r, -3 * h * r, -h * h * r},
                           {-36 * r, -3 * h * r, 36 * r, -3 * h * r},
                           {3 * h * r, -h * h * r, -3 * h * r, 4 * h * h * r}};
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) m(kAxial[i], kAxial[j]) = a[i][j];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) m(kBend[i], kBend[j]) = b[i][j] + ri[i][j];
  return m;
}

BeamMatrix BeamGeometricStiffness(double length_m, double axial_force_n) {
  const double h = length_m;
  const double g = axial_force_n / (30.0 * h);
  const double b[4][4] = {{36 * g, 3 * h * g, -36 * g, 3 * h * g},
                          {3 * h * g, 4 * h * h * g, -3 * h * g, -h * h * g},
                          {-36 * g, -3 * h * g, 36 * g, -3 * h * g},
                          {3 * h * g, -h * h * g, -3 * h * g, 4 * h * h * g}};
  BeamMatrix k = BeamMatrix::Zero();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) k(kBend[i], kBend[j]) = b[i][j];
  return k;
}

}  // namespace mbopt::multibody::floating_frame
