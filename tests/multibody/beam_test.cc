// Flexible links as co-rotational beams against closed forms: a cantilever's
// small tip deflection (P L^3 / 3 EI), its large deflection (the elastica,
// Mattiasson 1981), its first natural frequency, and the energy of a
// flexible pendulum swinging under gravity.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "worker/multibody/assembly.h"
#include "worker/multibody/flexible_link.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/static_equilibrium.h"

namespace mbopt::multibody {
namespace {

constexpr double kLength = 1.0, kBendingStiffness = 100.0, kAxialStiffness = 1e8, kMassPerLength = 1.0;

struct Cantilever {
  Model model;
  FlexibleLinkNodes nodes;
};

// Clamped at the origin (a fixed joint to ground at node 0), along x, with
// a downward tip force.
Cantilever MakeCantilever(int elements, double tip_force_n) {
  Cantilever c;
  FlexibleLinkSpec link;
  link.name = "beam";
  link.length_m = kLength;
  link.axial_stiffness_n = kAxialStiffness;
  link.bending_stiffness_n_m2 = kBendingStiffness;
  link.mass_per_length_kg_per_m = kMassPerLength;
  link.elements = elements;
  c.nodes = AddFlexibleLink(link, &c.model);
  Joint clamp;
  clamp.name = "clamp";
  clamp.kind = JointKind::kFixed;
  clamp.a = Point{kGround, Eigen::Vector2d::Zero(), "origin"};
  clamp.b = Point{c.nodes.end_a(), Eigen::Vector2d::Zero(), "a"};
  c.model.joints.push_back(clamp);
  if (tip_force_n != 0.0) {
    c.model.point_forces.push_back(
        PointForce{Point{c.nodes.end_b(), Eigen::Vector2d::Zero(), "b"}, Eigen::Vector2d(0.0, -tip_force_n),
                   std::nullopt});
  }
  EXPECT_TRUE(c.model.Validate().ok()) << c.model.Validate();
  return c;
}

// The static tip position (x, y) and rotation.
Eigen::Vector3d StaticTip(int elements, double tip_force_n) {
  const Cantilever c = MakeCantilever(elements, tip_force_n);
  const Mechanism m(c.model);
  const Assembly assembled = Assemble(m, 0.0);
  EXPECT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  Eigen::Vector3d tip = Eigen::Vector3d::Constant(NAN);
  StaticCounters counters;
  const spec::AnalysisFailure f = RunStaticEquilibrium(
      m, assembled.q, {0.0}, StaticOptions{},
      [&](const MotionSample& s) {
        tip = s.q.segment<3>(3 * c.nodes.end_b());
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  EXPECT_TRUE(f.ok()) << f.reason;
  return tip;
}

// Cubic Hermite elements are exact for a tip-loaded cantilever in linear
// theory; at P L^2 / EI = 1e-3 the geometric nonlinearity changes the tip
// deflection by about 1e-7 relative.
TEST(FlexibleLink, SmallTipDeflectionIsPLCubedOverThreeEI) {
  const double force = 1e-3 * kBendingStiffness / (kLength * kLength);
  const Eigen::Vector3d tip = StaticTip(4, force);
  const double expected = force * std::pow(kLength, 3) / (3.0 * kBendingStiffness);
  EXPECT_NEAR(-tip.y() / expected, 1.0, 1e-5);
  EXPECT_NEAR(-tip.z() / (force * kLength * kLength / (2.0 * kBendingStiffness)), 1.0, 1e-5);
}

// The elastica at P L^2 / EI = 1 (Mattiasson 1981; our own shooting solution
// gives the same digits): tip deflections v / L = 0.301721, u / L = 0.056433,
// tip rotation 0.461352 rad. The co-rotational error falls as 1 / N^2.
TEST(FlexibleLink, LargeTipDeflectionMatchesTheElastica) {
  const double force = kBendingStiffness / (kLength * kLength);
  double previous_error = INFINITY;
  for (int elements : {5, 10, 20}) {
    const Eigen::Vector3d tip = StaticTip(elements, force);
    const double v = -tip.y() / kLength, u = 1.0 - tip.x() / kLength, rotation = -tip.z();
    const double error = std::max({std::abs(v - 0.301721), std::abs(u - 0.056433), std::abs(rotation - 0.461352)});
    std::cout << elements << " elements: v/L " << v << ", u/L " << u << ", rotation " << rotation << "\n";
    EXPECT_LT(error, previous_error / 3.0);  // second order: a quarter per halving
    previous_error = error;
  }
  EXPECT_LT(previous_error, 2e-4);
}

// Released from rest under a suddenly applied small tip force, the tip
// oscillates about its static deflection at the first natural frequency
// omega_1 = 1.875104^2 sqrt(EI / (m L^4)) (lumped masses converge to it from
// below as 1 / N^2).
double FirstPeriod(int elements) {
  const double force = 1e-3 * kBendingStiffness / (kLength * kLength);
  const Cantilever c = MakeCantilever(elements, force);
  const Mechanism m(c.model);
  const Assembly assembled = Assemble(m, 0.0);
  EXPECT_TRUE(assembled.failure.ok());
  std::vector<double> times;
  for (int i = 0; i <= 2000; ++i) times.push_back(1.0 * i / 2000);
  ForwardDynamicsOptions options;
  options.relative_tolerance = 1e-7;
  options.absolute_tolerance = 1e-10;
  const double mean = -force * std::pow(kLength, 3) / (3.0 * kBendingStiffness);
  std::vector<double> crossings;  // upward crossings of the static deflection
  double last_t = 0.0, last_y = 0.0;
  ForwardDynamicsCounters counters;
  const spec::AnalysisFailure f = IntegrateForward(
      m, 0.0, assembled.q, assembled.v, times, options,
      [&](const MotionSample& s) {
        const double y = s.q[3 * c.nodes.end_b() + 1] - mean;
        if (s.t_s > 0.0 && last_y < 0.0 && y >= 0.0) crossings.push_back(last_t + (s.t_s - last_t) * -last_y / (y - last_y));
        last_t = s.t_s;
        last_y = y;
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  EXPECT_TRUE(f.ok()) << f.reason;
  if (crossings.size() < 3) return NAN;
  return (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
}

TEST(FlexibleLink, FirstNaturalFrequencyOfACantilever) {
  const double omega = std::pow(1.8751040687, 2) *
                       std::sqrt(kBendingStiffness / (kMassPerLength * std::pow(kLength, 4)));
  const double period = 2.0 * std::numbers::pi / omega;
  const double coarse = FirstPeriod(5) / period - 1.0, fine = FirstPeriod(10) / period - 1.0;
  std::cout << "period error: 5 elements " << coarse << ", 10 elements " << fine << "\n";
  // Lumped masses: second order in the element length (measured 1.94 % and
  // 0.51 %).
  EXPECT_GT(std::abs(coarse) / std::abs(fine), 3.0);
  EXPECT_LT(std::abs(fine), 6e-3);
}

// A flexible link pinned at one end, released horizontal under gravity:
// kinetic, gravitational and strain energy add up to a constant.
TEST(FlexibleLink, SwingingFlexiblePendulumConservesEnergy) {
  Model model;
  FlexibleLinkSpec link;
  link.name = "arm";
  link.length_m = kLength;
  link.axial_stiffness_n = 1e6;
  link.bending_stiffness_n_m2 = 50.0;
  link.mass_per_length_kg_per_m = kMassPerLength;
  link.elements = 6;
  const FlexibleLinkNodes nodes = AddFlexibleLink(link, &model);
  Joint pin;
  pin.name = "pin";
  pin.kind = JointKind::kRevolute;
  pin.a = Point{kGround, Eigen::Vector2d::Zero(), "origin"};
  pin.b = Point{nodes.end_a(), Eigen::Vector2d::Zero(), "a"};
  model.joints.push_back(pin);
  model.gravity_m_per_s2 = Eigen::Vector2d(0.0, -9.81);
  ASSERT_TRUE(model.Validate().ok());
  const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok());
  std::vector<double> times;
  for (int i = 0; i <= 200; ++i) times.push_back(1.0 * i / 200);
  ForwardDynamicsOptions options;
  options.relative_tolerance = 1e-9;
  options.absolute_tolerance = 1e-11;
  const double start = m.KineticEnergy(assembled.v) + m.PotentialEnergy(assembled.q);
  double drift = 0.0, strain = 0.0;
  ForwardDynamicsCounters counters;
  const spec::AnalysisFailure f = IntegrateForward(
      m, 0.0, assembled.q, assembled.v, times, options,
      [&](const MotionSample& s) {
        drift = std::max(drift, std::abs(m.KineticEnergy(s.v) + m.PotentialEnergy(s.q) - start));
        for (int e = 0; e < link.elements; ++e) {
          BeamLoads loads;
          m.BeamEndLoads(e, s.q, s.v, &loads);
          strain = std::max({strain, std::abs(loads.moment_a_n_m), std::abs(loads.moment_b_n_m)});
        }
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  ASSERT_TRUE(f.ok()) << f.reason;
  std::cout << "energy drift " << drift << " J of " << 0.5 * 9.81 << " J swung; bending moment up to " << strain
            << " N m\n";
  EXPECT_GT(strain, 0.1);  // the link does bend
  EXPECT_LT(drift, 1e-5);
}

}  // namespace
}  // namespace mbopt::multibody
