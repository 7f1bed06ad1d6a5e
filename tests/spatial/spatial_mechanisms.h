// Closed-loop spatial mechanisms that Simbody (mbopt_simbody_spatial_oracle)
// and mbopt both simulate, as plain numbers in world axes shared by the
// two: no Simbody and no mbopt types here (C++17, for the oracle).
//
// A mechanism: bodies (mass, principal moments in body axes, centre of
// mass and orientation at the start, velocities at the start: at rest
// unless given or a driver moves them) and joints. A joint is given by one world point and one world frame W
// (columns x, y, z) shared by its two sides in the initial pose; each side
// fixes it in its body. Kinds as in mbopt (worker/spatial/spatial_model.h):
// revolute about W's z, spherical, universal with the cross's axes W's x
// (in body a) and W's y (in body b), point on line (b's point on the line
// through the point along W's z, fixed in a), prismatic (b slides along
// W's z fixed in a, without turning). Values, per instant: each
// body's centre of mass (x, y, z, world, m) and rotation matrix (row by
// row), 12 numbers per body.
#pragma once

#include <array>
#include <cmath>
#include <vector>

namespace mbopt::oracle {

using Vec = std::array<double, 3>;
using Mat = std::array<double, 9>;  // row-major; columns are the axes

struct MechanismBody {
  double mass_kg = 1.0;
  Vec principal_moments_kg_m2{};  // about the body's own x, y, z
  Vec position_m{};                // centre of mass, world
  Mat orientation{1, 0, 0, 0, 1, 0, 0, 0, 1};  // body to world
  // At the start, world axes; consistent with the joints (neither code
  // corrects them much: both take the least change onto the joints).
  Vec velocity_m_per_s{};              // of the centre of mass
  Vec angular_velocity_rad_per_s{};
};

enum class MechanismJointKind { kRevolute, kSpherical, kUniversal, kPointOnLine, kPrismatic };

struct MechanismJoint {
  MechanismJointKind kind = MechanismJointKind::kRevolute;
  int a = -1, b = -1;  // body indices, -1 ground
  Vec point_m{};
  Mat axes{1, 0, 0, 0, 1, 0, 0, 0, 1};
};

struct Mechanism {
  std::vector<MechanismBody> bodies;
  std::vector<MechanismJoint> joints;
  Vec gravity_m_per_s2{0, 0, 0};
  // A constant-rate driver on one revolute joint (its rotation about W's z
  // starts at 0); -1: none.
  int driven_joint = -1;
  double driver_rate_rad_per_s = 0.0;
};

// Frames whose z axis is the world x, y or z axis (cyclic, so proper).
inline Mat AxesWithZAlongX() { return {0, 0, 1, 1, 0, 0, 0, 1, 0}; }
inline Mat AxesWithZAlongY() { return {0, 1, 0, 0, 0, 1, 1, 0, 0}; }
inline Mat AxesWithZAlongZ() { return {1, 0, 0, 0, 1, 0, 0, 0, 1}; }

// A slender box of length L along its body x axis and square section a:
// moments m (2 a^2) / 12 about x and m (L^2 + a^2) / 12 about y and z.
inline Vec BarMoments(double mass_kg, double length_m, double section_m) {
  const double axial = mass_kg * 2.0 * section_m * section_m / 12.0;
  const double transverse = mass_kg * (length_m * length_m + section_m * section_m) / 12.0;
  return {axial, transverse, transverse};
}

// The rotation taking the world x axis to the unit vector u (about the
// axis x cross u; half a turn about z for u = -x).
inline Mat XAlong(const Vec& u) {
  const double c = u[0];
  const Vec k{0.0, -u[2], u[1]};  // x cross u
  const double s2 = k[1] * k[1] + k[2] * k[2];
  if (s2 == 0.0) return c > 0.0 ? Mat{1, 0, 0, 0, 1, 0, 0, 0, 1} : Mat{-1, 0, 0, 0, -1, 0, 0, 0, 1};
  const double f = (1.0 - c) / s2;  // Rodrigues with unnormalized k
  const double kx = k[0], ky = k[1], kz = k[2];
  return {1 - f * (ky * ky + kz * kz), f * kx * ky - kz,           f * kx * kz + ky,
          f * kx * ky + kz,           1 - f * (kx * kx + kz * kz), f * ky * kz - kx,
          f * kx * kz - ky,           f * ky * kz + kx,           1 - f * (kx * kx + ky * ky)};
}

// Bricard's mechanism as the IFToMM library of computational benchmark
// problems states it: five bars of 1 m and 1 kg (square section 0.1 m)
// joined by six revolute joints into a loop with the ground, gravity
// 9.81 m/s^2 along -y, released at rest. Joint i at P_i, bar i from P_i to
// P_(i+1), the ground closing P_5 to P_0; the axes are y, z, x, y, z, x.
// Counting gives 0 degrees of freedom (5 x 6 - 6 x 5); the mechanism moves
// with 1, one joint equation being redundant throughout.
inline Mechanism Bricard() {
  const double l = 1.0;
  const Vec p[6] = {{0, 0, 0}, {l, 0, 0}, {l, -l, 0}, {l, -l, l}, {0, -l, l}, {0, 0, l}};
  const Mat axes[6] = {AxesWithZAlongY(), AxesWithZAlongZ(), AxesWithZAlongX(),
                       AxesWithZAlongY(), AxesWithZAlongZ(), AxesWithZAlongX()};
  Mechanism m;
  for (int i = 0; i < 5; ++i) {
    const Vec& a = p[i];
    const Vec& b = p[i + 1];
    MechanismBody bar;
    bar.mass_kg = 1.0;
    bar.principal_moments_kg_m2 = BarMoments(1.0, l, 0.1);
    bar.position_m = {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
    bar.orientation = XAlong({(b[0] - a[0]) / l, (b[1] - a[1]) / l, (b[2] - a[2]) / l});
    m.bodies.push_back(bar);
  }
  for (int i = 0; i < 6; ++i) {
    m.joints.push_back({MechanismJointKind::kRevolute, i - 1, i == 5 ? -1 : i, p[i], axes[i]});
  }
  m.gravity_m_per_s2 = {0, -9.81, 0};
  return m;
}

// A spatial four-bar RSSR under gravity (-y), released at rest: a crank
// on a revolute joint about world z at the origin, a coupler on spherical
// joints, a rocker on a revolute joint about world x at (0.6, 0.5, -0.1).
// Crank 0.3 m along x, coupler from (0.3, 0, 0) to the rocker's tip
// (0.6, 0.5, 0.3) (0.66 m), rocker 0.4 m along z. Two degrees of freedom:
// the loop's one and the coupler's spin about its own line.
inline Mechanism Rssr() {
  const Vec o{0, 0, 0}, b{0.3, 0, 0}, c{0.6, 0.5, 0.3}, d{0.6, 0.5, -0.1};
  auto bar = [](const Vec& from, const Vec& to, double mass_kg) {
    const Vec u{to[0] - from[0], to[1] - from[1], to[2] - from[2]};
    const double length = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    MechanismBody body;
    body.mass_kg = mass_kg;
    body.principal_moments_kg_m2 = BarMoments(mass_kg, length, 0.03);
    body.position_m = {(from[0] + to[0]) / 2, (from[1] + to[1]) / 2, (from[2] + to[2]) / 2};
    body.orientation = XAlong({u[0] / length, u[1] / length, u[2] / length});
    return body;
  };
  Mechanism m;
  m.bodies = {bar(o, b, 0.8), bar(b, c, 1.2), bar(d, c, 1.0)};
  m.joints.push_back({MechanismJointKind::kRevolute, -1, 0, o, AxesWithZAlongZ()});
  m.joints.push_back({MechanismJointKind::kSpherical, 0, 1, b, AxesWithZAlongZ()});
  m.joints.push_back({MechanismJointKind::kRevolute, -1, 2, d, AxesWithZAlongX()});
  m.joints.push_back({MechanismJointKind::kSpherical, 1, 2, c, AxesWithZAlongZ()});
  m.gravity_m_per_s2 = {0, -9.81, 0};
  return m;
}

// A Cardan (universal-joint) drive shaft: an input shaft along world x on
// a revolute joint driven at 2 pi rad/s, an output shaft at beta = 0.5 rad
// to it in the x-y plane, held by the cross at the origin and a bearing
// (point on line) at its far end, no gravity. Shafts 1 m long, 2 kg,
// moments (0.01, 0.17, 0.17) kg m^2 about their own x (the shaft) and the
// transverse axes. The cross's axes start along world z (in the input)
// and normal to the output in the x-y plane. The output turns at
//   w2 / w1 = cos beta / (1 - sin^2 beta sin^2(w1 t)).
inline constexpr double kCardanAngleRad = 0.5;
inline constexpr double kCardanInputRateRadPerS = 6.283185307179586;
inline Mechanism CardanShaft() {
  const double cb = std::cos(kCardanAngleRad), sb = std::sin(kCardanAngleRad);
  MechanismBody input, output;
  input.mass_kg = output.mass_kg = 2.0;
  input.principal_moments_kg_m2 = output.principal_moments_kg_m2 = {0.01, 0.17, 0.17};
  input.position_m = {-0.5, 0, 0};
  output.position_m = {0.5 * cb, 0.5 * sb, 0};
  output.orientation = XAlong({cb, sb, 0});
  Mechanism m;
  m.bodies = {input, output};
  m.joints.push_back({MechanismJointKind::kRevolute, -1, 0, {-1.0, 0, 0}, AxesWithZAlongX()});
  // x = world z, y = (-sin b, cos b, 0), z = x cross y = (-cos b, -sin b, 0).
  m.joints.push_back({MechanismJointKind::kUniversal, 0, 1, {0, 0, 0}, {0, -sb, -cb, 0, cb, -sb, 1, 0, 0}});
  // The bearing's line along the output shaft: W's z = (cos b, sin b, 0).
  m.joints.push_back({MechanismJointKind::kPointOnLine, -1, 1, {cb, sb, 0}, {-sb, 0, cb, cb, 0, sb, 0, 1, 0}});
  m.driven_joint = 0;
  m.driver_rate_rad_per_s = kCardanInputRateRadPerS;
  return m;
}

// A ten-bar chain on spherical joints closed back to ground (the spatial
// speed benchmark's mechanism, bench/spatial): bars of 1 m and 1 kg
// (square section 0.1 m) laid end to end in the horizontal plane z = 0,
// bar i along the angle -60 + 12 (i + 1/2) degrees from world x, so the
// chain bows as an arc from the ground point at the origin to a second
// ground point 8.29 m away along x. Spherical joints at the origin,
// between the bars and at the far end (the closing one), gravity 9.81 m/s^2
// along -z, released at rest: the arc falls and swings through below its
// ends. 60 - 33 = 27 degrees of freedom, ten of them the bars' spins about
// their own axes (not excited).
inline constexpr int kChainBars = 10;
inline Mechanism SphericalChain() {
  const double pi = 3.14159265358979323846;
  Mechanism m;
  Vec joint{0, 0, 0};
  for (int i = 0; i < kChainBars; ++i) {
    const double angle = -pi / 3 + (2 * pi / 3) * (i + 0.5) / kChainBars;
    const Vec u{std::cos(angle), std::sin(angle), 0};
    MechanismBody bar;
    bar.mass_kg = 1.0;
    bar.principal_moments_kg_m2 = BarMoments(1.0, 1.0, 0.1);
    bar.position_m = {joint[0] + u[0] / 2, joint[1] + u[1] / 2, joint[2] + u[2] / 2};
    bar.orientation = XAlong(u);
    m.bodies.push_back(bar);
    m.joints.push_back({MechanismJointKind::kSpherical, i - 1, i, joint, AxesWithZAlongZ()});
    joint = {joint[0] + u[0], joint[1] + u[1], joint[2] + u[2]};
  }
  m.joints.push_back({MechanismJointKind::kSpherical, kChainBars - 1, -1, joint, AxesWithZAlongZ()});
  m.gravity_m_per_s2 = {0, 0, -9.81};
  return m;
}

// The spatial rigid slider-crank of the IFToMM library of computational
// benchmark problems, from its published input data (SI, gravity 9.81
// along -z, no friction, 5 s). A crank on a revolute joint about world x
// at A = (0, 0.1, 0.12), its centre of mass on the hinge, its pin B 0.08
// above A at the start, turning at 6 rad/s; a connecting rod of 0.3 from B
// (spherical joint) to C = (0.2, 0, 0) on a slider (a block on a prismatic
// joint along world x through the origin), held there by a universal joint
// whose cross has one axis along x in the slider and the other normal to x
// and to the rod, (0, 2, -1) / sqrt 5, in the rod. C's x is
// sqrt(0.3^2 - 0.1^2 - 0.2^2) = 0.2. The start's velocities, from the
// crank's rate by the loop's closed form: B moves at (0, -0.48, 0), the rod
// turns at (1.92, -0.96, 0.48) (its component along (0, -1, -2), which the
// cross holds, is zero) and the slider moves at 0.24 along x. One degree of
// freedom. Bodies in this order: crank, rod, slider.
inline constexpr double kSliderCrankRateRadPerS = 6.0;
inline Mechanism SpatialSliderCrank() {
  const double w = kSliderCrankRateRadPerS;
  const double root5 = std::sqrt(5.0);
  const Vec a{0, 0.1, 0.12}, b{0, 0.1, 0.2}, c{0.2, 0, 0};
  MechanismBody crank, rod, slider;
  crank.mass_kg = 0.12;
  // Along x (the hinge), y and z (along the crank at the start).
  crank.principal_moments_kg_m2 = {1e-4, 1e-4, 1e-5};
  crank.position_m = a;
  crank.angular_velocity_rad_per_s = {w, 0, 0};
  rod.mass_kg = 0.5;
  rod.principal_moments_kg_m2 = {4e-4, 4e-3, 4e-3};  // about its own axis (body x), transverse
  rod.position_m = {(b[0] + c[0]) / 2, (b[1] + c[1]) / 2, (b[2] + c[2]) / 2};
  // Body x along the rod (C - B) / 0.3, y along the cross's rod axis.
  const Vec u{2.0 / 3, -1.0 / 3, -2.0 / 3}, n{0, 2 / root5, -1 / root5};
  const Vec k{u[1] * n[2] - u[2] * n[1], u[2] * n[0] - u[0] * n[2], u[0] * n[1] - u[1] * n[0]};
  rod.orientation = {u[0], n[0], k[0], u[1], n[1], k[1], u[2], n[2], k[2]};
  // The closed form above is linear in the crank's rate w.
  rod.angular_velocity_rad_per_s = {0.32 * w, -0.16 * w, 0.08 * w};
  rod.velocity_m_per_s = {0.02 * w, -0.04 * w, 0};  // midway between B's and C's
  slider.mass_kg = 2.0;
  slider.principal_moments_kg_m2 = {1e-4, 1e-4, 1e-4};
  slider.position_m = c;
  slider.velocity_m_per_s = {0.04 * w, 0, 0};
  Mechanism m;
  m.bodies = {crank, rod, slider};
  m.joints.push_back({MechanismJointKind::kRevolute, -1, 0, a, AxesWithZAlongX()});
  m.joints.push_back({MechanismJointKind::kSpherical, 0, 1, b, AxesWithZAlongZ()});
  m.joints.push_back({MechanismJointKind::kPrismatic, -1, 2, {0, 0, 0}, AxesWithZAlongX()});
  // The cross: W's x = world x (in the slider), W's y = n (in the rod).
  const Vec z{0, 1 / root5, 2 / root5};  // x cross n
  m.joints.push_back({MechanismJointKind::kUniversal, 2, 1, c, {1, n[0], z[0], 0, n[1], z[1], 0, n[2], z[2]}});
  m.gravity_m_per_s2 = {0, 0, -9.81};
  return m;
}

}  // namespace mbopt::oracle
