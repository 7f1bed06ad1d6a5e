// Kinetostatic formulation: the rigid four-bar check values of
// benchmarks/fourbar_stress.md and equilibrium invariants.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "tests/linkage/follow_linkage.h"
#include "tests/linkage/linkage_scenes.h"
#include "worker/multibody/linkage_analysis.h"

namespace mbopt {
namespace {

using linkage_testing::FourBarScene;
using linkage_testing::kFourBarAllowablePa;

// The benchmark prints 4 decimals of sigma/allowable.
constexpr double kRatioTol = 6e-5;

struct Ratios {
  double crank, coupler, rocker, mass;
};

Ratios MaxStressRatios(const std::vector<double>& areas) {
  const spec::AnalysisReport r = multibody::AnalyzeLinkageScene(FourBarScene(), areas);
  EXPECT_TRUE(r.ok()) << r.failure.reason;
  EXPECT_EQ(r.formulation, spec::Formulation::kKinetostatic);
  EXPECT_EQ(r.counters.time_steps, 0);
  double m[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(r.outputs[static_cast<size_t>(k)].series.size(), 7u);
    for (const auto& series : r.outputs[static_cast<size_t>(k)].series) {
      EXPECT_EQ(series.size(), 101u);
      for (double v : series) m[k] = std::max(m[k], std::abs(v) / kFourBarAllowablePa);
    }
  }
  return {m[0], m[1], m[2], r.outputs[3].series[0][0]};
}

TEST(RigidFourBarStress, InitialDesignMatchesCheckValues) {
  const Ratios r = MaxStressRatios({0.1, 0.1, 0.1});
  EXPECT_NEAR(r.crank, 0.2548, kRatioTol);
  EXPECT_NEAR(r.coupler, 0.0640, kRatioTol);
  EXPECT_NEAR(r.rocker, 0.0499, kRatioTol);
  // rho * (l1 + l2 + l3) * 0.1 = 546.2 kg (the report's 546).
  EXPECT_NEAR(r.mass, 2757 * (0.3048 + 0.9144 + 0.762) * 0.1, 1e-9);
}

TEST(RigidFourBarStress, ReportOptimumMatchesCheckValues) {
  const Ratios r = MaxStressRatios({9.65e-4, 3.92e-4, 2.69e-4});
  EXPECT_NEAR(r.crank, 0.9356, kRatioTol);
  EXPECT_NEAR(r.coupler, 1.0226, kRatioTol);
  EXPECT_NEAR(r.rocker, 0.9629, kRatioTol);
}

TEST(RigidFourBarStress, SohoniHaugOptimumMatchesCheckValues) {
  const Ratios r = MaxStressRatios({1.03e-3, 6.21e-4, 1.17e-4});
  EXPECT_NEAR(r.crank, 1.0753, kRatioTol);
  EXPECT_NEAR(r.coupler, 0.8125, kRatioTol);
  EXPECT_NEAR(r.rocker, 1.4600, kRatioTol);
}

// Without gravity every moment is linear in the areas (inertia loads scale
// with A), so the stress 4 sqrt(pi) M / A^1.5 scales as A^-1/2 when all
// areas scale together.
TEST(RigidFourBarStress, StressScalesAsInverseSquareRootOfUniformAreaScale) {
  const Ratios a = MaxStressRatios({0.1, 0.1, 0.1});
  const Ratios b = MaxStressRatios({0.025, 0.025, 0.025});
  EXPECT_NEAR(b.crank / a.crank, 2.0, 1e-9);
  EXPECT_NEAR(b.rocker / a.rocker, 2.0, 1e-9);
}

// Pinned ends carry no moment; the crank root carries the drive torque; the
// drive torque balances the power: T omega = d/dt(kinetic energy) minus the
// power of gravity (when the scene declares it).
void CheckEquilibriumAndPower(bool gravity) {
  spec::Scene scene = FourBarScene();
  if (gravity) scene.effects.gravity_m_per_s2 = linkage_testing::At(0.0, -9.81);
  const double omega = 10 * std::numbers::pi;
  const Eigen::Vector2d g = gravity ? Eigen::Vector2d(0.0, -9.81) : Eigen::Vector2d::Zero();
  std::vector<double> times;
  for (int i = 0; i <= 40; ++i) times.push_back(0.005 * i);
  int instants = 0;
  const auto at = [&](const multibody::LinkageSystem& system, const multibody::LinkageState& s,
                      const multibody::RigidBarLoads& loads) {
    ++instants;
    double scale = std::abs(loads.drive_torque_n_m);
    for (size_t l = 0; l < 3; ++l) {
      for (double m : loads.node_moment_n_m[l]) scale = std::max(scale, std::abs(m));
    }
    // Round-off of the 9x9 multiplier solve relative to the largest moment.
    const double tol = 1e-10 * scale;
    EXPECT_NEAR(loads.node_moment_n_m[0].back(), 0.0, tol);   // crank at A
    EXPECT_NEAR(loads.node_moment_n_m[1].front(), 0.0, tol);  // coupler at A
    EXPECT_NEAR(loads.node_moment_n_m[1].back(), 0.0, tol);   // coupler at B
    EXPECT_NEAR(loads.node_moment_n_m[2].front(), 0.0, tol);  // rocker at O4
    EXPECT_NEAR(loads.node_moment_n_m[2].back(), 0.0, tol);   // rocker at B
    EXPECT_NEAR(loads.node_moment_n_m[0].front(), -loads.drive_torque_n_m, tol);  // crank root
    // Slender rods: dT/dt = m (v_a.a_a/3 + (v_a.a_b + v_b.a_a)/6 + v_b.a_b/3);
    // gravity's power m g.(v_a + v_b)/2.
    double power = 0.0;
    for (const multibody::LinkageLink& l : system.links) {
      const double mass = l.mass_per_length_kg_per_m() * l.length_m;
      const auto& va = s.velocity_m_per_s[static_cast<size_t>(l.joint_a)];
      const auto& vb = s.velocity_m_per_s[static_cast<size_t>(l.joint_b)];
      const auto& aa = s.acceleration_m_per_s2[static_cast<size_t>(l.joint_a)];
      const auto& ab = s.acceleration_m_per_s2[static_cast<size_t>(l.joint_b)];
      power += mass * (va.dot(aa) / 3 + (va.dot(ab) + vb.dot(aa)) / 6 + vb.dot(ab) / 3);
      power -= mass * g.dot(va + vb) / 2;
    }
    EXPECT_NEAR(loads.drive_torque_n_m * omega, power, 1e-10 * scale * omega);
  };
  ASSERT_TRUE(linkage_testing::FollowLinkage(scene, {0.01, 0.02, 0.03}, times, true, at));
  EXPECT_EQ(instants, 41);
}

TEST(Kinetostatics, PinnedEndsAreMomentFreeAndPowerBalances) { CheckEquilibriumAndPower(false); }

TEST(Kinetostatics, GravityEntersOnlyWhenDeclaredAndBalancesPower) {
  CheckEquilibriumAndPower(true);
  // Declared gravity changes the drive torque; absent gravity does not exist.
  spec::Scene with = FourBarScene();
  with.effects.gravity_m_per_s2 = linkage_testing::At(0.0, -9.81);
  const auto a = multibody::AnalyzeLinkageScene(FourBarScene(), {0.01, 0.02, 0.03});
  const auto b = multibody::AnalyzeLinkageScene(with, {0.01, 0.02, 0.03});
  ASSERT_TRUE(a.ok());
  ASSERT_TRUE(b.ok());
  double diff = 0.0;
  for (size_t i = 0; i < 101; ++i) {
    diff = std::max(diff, std::abs(a.outputs[4].series[0][i] - b.outputs[4].series[0][i]));
  }
  // Gravity torque of the crank alone is up to m g l / 2 = 4.1 N m here.
  EXPECT_GT(diff, 1.0);
}

}  // namespace
}  // namespace mbopt
