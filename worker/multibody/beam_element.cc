#include "worker/multibody/beam_element.h"

#include <cmath>
#include <numbers>

namespace mbopt::multibody {
namespace {

// Into (-pi, pi]: the chord angle comes from atan2, whose branch cut must
// not show in the element's small local rotations.
double Wrapped(double angle) {
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  angle = std::remainder(angle, kTwoPi);
  return angle <= -std::numbers::pi ? angle + kTwoPi : angle;
}

}  // namespace

bool EvaluateBeam(const BeamElement& e, const BeamNodes& x, const BeamNodes* x_dot, BeamLoads* loads) {
  const double dx = x[3] - x[0], dy = x[4] - x[1];
  const double length = std::hypot(dx, dy);
  if (!(length > 0.0)) return false;
  const double beta = std::atan2(dy, dx);
  const double c = dx / length, s = dy / length;
  loads->chord_length_m = length;
  loads->chord_cos = c;
  loads->chord_sin = s;
  loads->stretch_m = length - e.length_m;
  loads->rotation_a_rad = Wrapped(x[2] - beta - e.angle_a_rad);
  loads->rotation_b_rad = Wrapped(x[5] - beta - e.angle_b_rad);
  const double k = 2.0 * e.bending_stiffness_n_m2 / e.length_m;
  loads->axial_n = e.axial_stiffness_n * loads->stretch_m / e.length_m;
  loads->moment_a_n_m = k * (2.0 * loads->rotation_a_rad + loads->rotation_b_rad);
  loads->moment_b_n_m = k * (loads->rotation_a_rad + 2.0 * loads->rotation_b_rad);
  if (x_dot != nullptr && e.damping_s > 0.0) {
    const double stretch_rate = c * ((*x_dot)[3] - (*x_dot)[0]) + s * ((*x_dot)[4] - (*x_dot)[1]);
    // d beta / dt = z . x' / l with z = (s, -c, 0, -s, c, 0).
    const double chord_rate = (-s * ((*x_dot)[3] - (*x_dot)[0]) + c * ((*x_dot)[4] - (*x_dot)[1])) / length;
    const double rate_a = (*x_dot)[2] - chord_rate, rate_b = (*x_dot)[5] - chord_rate;
    loads->axial_n += e.damping_s * e.axial_stiffness_n * stretch_rate / e.length_m;
    loads->moment_a_n_m += e.damping_s * k * (2.0 * rate_a + rate_b);
    loads->moment_b_n_m += e.damping_s * k * (rate_a + 2.0 * rate_b);
  }
  return true;
}

BeamNodes BeamInternalForces(const BeamLoads& loads) {
  const double length = loads.chord_length_m, c = loads.chord_cos, s = loads.chord_sin;
  BeamNodes r, z;
  r << -c, -s, 0.0, c, s, 0.0;
  z << s, -c, 0.0, -s, c, 0.0;
  BeamNodes f = loads.axial_n * r - (loads.moment_a_n_m + loads.moment_b_n_m) / length * z;
  f[2] += loads.moment_a_n_m;
  f[5] += loads.moment_b_n_m;
  return f;
}

double BeamStrainEnergy(const BeamElement& e, const BeamLoads& loads) {
  const double ta = loads.rotation_a_rad, tb = loads.rotation_b_rad;
  return 0.5 * e.axial_stiffness_n * loads.stretch_m * loads.stretch_m / e.length_m +
         2.0 * e.bending_stiffness_n_m2 / e.length_m * (ta * ta + ta * tb + tb * tb);
}

}  // namespace mbopt::multibody
