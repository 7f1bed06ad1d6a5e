// Textbook mechanisms as multibody models, for the engine's tests: each
// documents its frames and where its closed-form answers come from.
#pragma once

#include <cmath>
#include <numbers>
#include <string>

#include "worker/multibody/model.h"

namespace mbopt::multibody::testing {

// A uniform bar of mass m and length L along its body x axis, centre of mass
// at its middle; markers are at -L/2 ("a") and +L/2 ("b").
inline Body Bar(const std::string& name, double mass_kg, double length_m, Eigen::Vector2d centre, double angle_rad) {
  Body b;
  b.name = name;
  b.mass_kg = mass_kg;
  b.inertia_kg_m2 = mass_kg * length_m * length_m / 12.0;
  b.position_m = centre;
  b.angle_rad = angle_rad;
  return b;
}

inline Point At(int body, double x, double y = 0.0) { return Point{body, Eigen::Vector2d(x, y), ""}; }

inline Joint Revolute(const std::string& name, Point a, Point b) {
  Joint j;
  j.name = name;
  j.kind = JointKind::kRevolute;
  j.a = a;
  j.b = b;
  return j;
}

// Slider-crank: crank (length r) pinned at the origin and driven at constant
// speed omega from angle 0, rod (length l) from the crank tip to a slider
// (mass 1 kg) on the x axis. Slider position x = r cos(th) + sqrt(l^2 - r^2
// sin^2(th)), th = omega t.
inline Model SliderCrank(double r, double l, double omega) {
  Model m;
  m.bodies.push_back(Bar("crank", 1.0, r, {r / 2, 0.0}, 0.0));
  m.bodies.push_back(Bar("rod", 2.0, l, {r + l / 2, 0.0}, 0.0));
  Body slider;
  slider.name = "slider";
  slider.mass_kg = 1.0;
  slider.inertia_kg_m2 = 0.01;
  slider.position_m = {r + l, 0.0};
  m.bodies.push_back(slider);
  m.joints.push_back(Revolute("O", At(kGround, 0.0), At(0, -r / 2)));
  m.joints.push_back(Revolute("A", At(0, r / 2), At(1, -l / 2)));
  m.joints.push_back(Revolute("B", At(1, l / 2), At(2, 0.0)));
  Joint slide;
  slide.name = "slide";
  slide.kind = JointKind::kPrismatic;
  slide.a = At(kGround, 0.0);
  slide.b = At(2, 0.0);
  m.joints.push_back(slide);
  Driver d;
  d.joint = 0;
  d.profile.kind = Profile::Kind::kConstantRate;
  d.profile.rate = omega;
  m.drivers.push_back(d);
  return m;
}

// A uniform bar (mass m, length L) pinned at its end "a" to the origin,
// released at rest at angle theta0 from the downward vertical (the body x
// axis points from the pin to the free end; angle phi = theta - pi/2).
inline Model Pendulum(double mass_kg, double length_m, double theta0_rad, double g = 9.81) {
  Model m;
  const double phi = theta0_rad - std::numbers::pi / 2;
  m.bodies.push_back(Bar("bar", mass_kg, length_m, {0.5 * length_m * std::cos(phi), 0.5 * length_m * std::sin(phi)}, phi));
  m.joints.push_back(Revolute("pin", At(kGround, 0.0), At(0, -length_m / 2)));
  m.gravity_m_per_s2 = Eigen::Vector2d(0.0, -g);
  return m;
}

// Two uniform bars in a chain from the origin, at absolute angles phi1, phi2
// from the x axis, at rest.
inline Model DoublePendulum(double phi1, double phi2) {
  Model m;
  const double l1 = 1.0, l2 = 0.7;
  const Eigen::Vector2d tip(l1 * std::cos(phi1), l1 * std::sin(phi1));
  m.bodies.push_back(Bar("upper", 1.0, l1, tip / 2, phi1));
  m.bodies.push_back(Bar("lower", 0.5, l2, tip + 0.5 * l2 * Eigen::Vector2d(std::cos(phi2), std::sin(phi2)), phi2));
  m.joints.push_back(Revolute("shoulder", At(kGround, 0.0), At(0, -l1 / 2)));
  m.joints.push_back(Revolute("elbow", At(0, l1 / 2), At(1, -l2 / 2)));
  m.gravity_m_per_s2 = Eigen::Vector2d(0.0, -9.81);
  return m;
}

// SUNDIALS' slider-crank (idasSlCrank_FSA_dns.c; Haug, Intermediate
// Dynamics, example 6.1.8) in absolute coordinates. Its generalized
// coordinates are the crank angle q, the slider position x and the rod angle
// p; the crank (inertia J1 = 1 about its pivot, half-length a = 0.5 as the
// example names it, tip at distance a) turns about the origin; the rod (mass
// m2 = 1 carried at the slider point, inertia J2 = 2 about it, length 1) has
// its body axis at angle p and the crank tip at rod point (-1, 0), so the
// example's constraints x - cos p - a cos q = 0 and -sin p - a sin q = 0 are
// the two rows of the tip joint. A spring-damper
// (k, c, free length 1) joins the crank's middle to the rod's middle; a
// constant force F = 1 along x acts at rod point (1, 0), which gives the
// example's generalized forces F on x and -F sin p on p. The slider point runs
// on the x axis (a point-on-line joint: the example has no slider body).
inline Model SundialsSliderCrank(double k, double c) {
  constexpr double a = 0.5;
  const double q0 = std::numbers::pi / 2, p0 = std::asin(-a), x0 = std::cos(p0);
  Model m;
  Body crank;
  crank.name = "crank";
  crank.mass_kg = 1.0;  // its centre of mass is the pivot: the mass never moves
  crank.inertia_kg_m2 = 1.0;
  crank.angle_rad = q0;
  m.bodies.push_back(crank);
  Body rod;
  rod.name = "rod";
  rod.mass_kg = 1.0;
  rod.inertia_kg_m2 = 2.0;
  rod.position_m = {x0, 0.0};
  rod.angle_rad = p0;
  m.bodies.push_back(rod);
  m.joints.push_back(Revolute("pivot", At(kGround, 0.0), At(0, 0.0)));
  m.joints.push_back(Revolute("tip", At(0, a), At(1, -1.0)));
  Joint slot;
  slot.name = "slot";
  slot.kind = JointKind::kPointOnLine;
  slot.a = At(kGround, 0.0);
  slot.b = At(1, 0.0);
  m.joints.push_back(slot);
  SpringDamper s;
  s.name = "spring";
  s.a = At(0, a / 2);
  s.b = At(1, -0.5);
  s.free_length_m = 1.0;
  s.stiffness_n_per_m = k;
  s.damping_n_s_per_m = c;
  m.springs.push_back(s);
  m.point_forces.push_back(PointForce{At(1, 1.0), Eigen::Vector2d(1.0, 0.0), std::nullopt});
  return m;
}

// The ten-body chain of tests/oracle/simbody_oracle.h (TenBodyChain): five
// rockers hanging from ground pivots at x = 0..4 at angle theta, four
// couplers joining their lower ends (parallelograms), and a free pendulum on
// the last rocker's lower end at pendulum_angle; at rest, under gravity.
inline Model TenBodyChain(double theta = -1.2, double pendulum_angle = -2.0) {
  Model m;
  const Eigen::Vector2d down(std::cos(theta), std::sin(theta));
  for (int i = 0; i < 5; ++i) {
    m.bodies.push_back(Bar("rocker" + std::to_string(i), 1.0, 1.0, Eigen::Vector2d(i, 0.0) + 0.5 * down, theta));
    Joint pivot = Revolute("pivot" + std::to_string(i), Point{kGround, Eigen::Vector2d(i, 0.0), ""}, At(i, -0.5));
    if (i == 0) pivot.initial_value = theta;
    m.joints.push_back(pivot);
  }
  for (int j = 0; j < 4; ++j) {
    const int body = static_cast<int>(m.bodies.size());
    m.bodies.push_back(Bar("coupler" + std::to_string(j), 1.0, 1.0, Eigen::Vector2d(j + 0.5, 0.0) + down, 0.0));
    m.joints.push_back(Revolute("left" + std::to_string(j), At(j, 0.5), At(body, -0.5)));
    m.joints.push_back(Revolute("right" + std::to_string(j), At(body, 0.5), At(j + 1, 0.5)));
  }
  const int pendulum = static_cast<int>(m.bodies.size());
  const Eigen::Vector2d hang(std::cos(pendulum_angle), std::sin(pendulum_angle));
  m.bodies.push_back(Bar("pendulum", 0.5, 0.6, Eigen::Vector2d(4.0, 0.0) + down + 0.3 * hang, pendulum_angle));
  Joint hinge = Revolute("hinge", At(4, 0.5), At(pendulum, -0.3));
  hinge.initial_value = pendulum_angle - theta;
  m.joints.push_back(hinge);
  m.gravity_m_per_s2 = Eigen::Vector2d(0.0, -9.81);
  return m;
}

// A closed chain of `rods` (>= 4) uniform rods (1 kg, 1 m) between two
// ground pins rods - 2 m apart: the first two rods start 60 degrees below
// the horizontal, the last two 60 degrees above it, the rest horizontal (a
// closed start); released at rest under gravity. rods - 2 degrees of freedom
// (8 for ten rods: the issue-30 chain).
inline Model RodChain(int rods) {
  Model m;
  const double kSlope = std::numbers::pi / 3;
  Eigen::Vector2d at(0.0, 0.0);
  for (int i = 0; i < rods; ++i) {
    const double angle = i < 2 ? -kSlope : i >= rods - 2 ? kSlope : 0.0;
    const Eigen::Vector2d along(std::cos(angle), std::sin(angle));
    m.bodies.push_back(Bar("rod" + std::to_string(i), 1.0, 1.0, at + 0.5 * along, angle));
    const Point previous = i == 0 ? Point{kGround, Eigen::Vector2d::Zero(), ""} : At(i - 1, 0.5);
    m.joints.push_back(Revolute("pin" + std::to_string(i), previous, At(i, -0.5)));
    at += along;
  }
  m.joints.push_back(Revolute("pin" + std::to_string(rods), At(rods - 1, 0.5),
                              Point{kGround, Eigen::Vector2d(rods - 2.0, 0.0), ""}));
  m.gravity_m_per_s2 = Eigen::Vector2d(0.0, -9.81);
  return m;
}

}  // namespace mbopt::multibody::testing
