// Kinematic formulation: closed-form four-bar kinematics (Freudenstein),
// the landing-gear check values of benchmarks/landing_gear.md, and failures
// reported as data (no assembly, lock, wrong mobility).
#include <cmath>
#include <numbers>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/linkage/follow_linkage.h"
#include "tests/linkage/linkage_scenes.h"
#include "worker/multibody/linkage_analysis.h"

namespace mbopt {
namespace {

using linkage_testing::FourBarScene;
using linkage_testing::LandingGearDesign;
using linkage_testing::LandingGearScene;
using ::testing::HasSubstr;

// Newton closes the loops to 1e-11 m; velocities and
// accelerations come from linear solves: relative agreement ~1e-10.
constexpr double kAngleTolRad = 1e-9;
constexpr double kRelativeTol = 1e-8;
// The check values are printed to 2 decimals (mm), 4 decimals (rad), and
// F to 2 decimals (5 significant digits at 0.884).
constexpr double kMmTol = 0.006;
constexpr double kRadTol = 6e-5;

double Wrap(double a) { return std::remainder(a, 2 * std::numbers::pi); }

TEST(LinkageKinematics, FourBarFollowsFreudensteinClosedForm) {
  const spec::Scene scene = FourBarScene();
  const double a = linkage_testing::kCrankM, b = linkage_testing::kCouplerM,
               c = linkage_testing::kRockerM, d = linkage_testing::kGroundM;
  const double w2 = 10 * std::numbers::pi;
  const double k1 = d / a, k2 = d / c, k3 = (a * a - b * b + c * c + d * d) / (2 * a * c);
  int root_sign = 0;
  std::vector<double> times;
  for (int i = 0; i <= 50; ++i) times.push_back(0.004 * i);  // one revolution in 0.2 s
  int instants = 0;
  const auto at = [&](const multibody::LinkageSystem& system, const multibody::LinkageState& s,
                      const multibody::RigidBarLoads&) {
    ++instants;
    const double t = s.time_s;
    const std::vector<multibody::LinkageLink>& links = system.links;
    const double th2 = -std::numbers::pi / 2 + w2 * t;
    const double th3 = s.LinkAngle(links[1]);
    const double th4 = s.LinkAngle(links[2]);
    // Freudenstein: K1 cos th4 - K2 cos th2 + K3 = cos(th2 - th4), solved by
    // the half-angle substitution; the branch (root sign) must not change.
    const double ca = std::cos(th2) - k1 - k2 * std::cos(th2) + k3;
    const double cb = -2 * std::sin(th2);
    const double cc = k1 - (k2 + 1) * std::cos(th2) + k3;
    const double disc = std::sqrt(cb * cb - 4 * ca * cc);
    const double plus = 2 * std::atan2(-cb + disc, 2 * ca);
    const double minus = 2 * std::atan2(-cb - disc, 2 * ca);
    const int sign = std::abs(Wrap(th4 - plus)) < std::abs(Wrap(th4 - minus)) ? 1 : -1;
    if (root_sign == 0) root_sign = sign;
    EXPECT_EQ(sign, root_sign) << "branch changed at t = " << t;
    EXPECT_NEAR(Wrap(th4 - (sign > 0 ? plus : minus)), 0.0, kAngleTolRad) << "t = " << t;
    // Velocity loop closure, closed form.
    const double w3 = a * w2 * std::sin(th4 - th2) / (b * std::sin(th3 - th4));
    const double w4 = a * w2 * std::sin(th2 - th3) / (c * std::sin(th4 - th3));
    EXPECT_NEAR(s.LinkAngularVelocity(links[1]), w3, kRelativeTol * std::abs(w2)) << t;
    EXPECT_NEAR(s.LinkAngularVelocity(links[2]), w4, kRelativeTol * std::abs(w2)) << t;
    // Acceleration loop: b a3 e3p - c a4 e4p = a w2^2 e2 + b w3^2 e3 - c w4^2 e4 (Cramer).
    const double rx = a * w2 * w2 * std::cos(th2) + b * w3 * w3 * std::cos(th3) -
                      c * w4 * w4 * std::cos(th4);
    const double ry = a * w2 * w2 * std::sin(th2) + b * w3 * w3 * std::sin(th3) -
                      c * w4 * w4 * std::sin(th4);
    const double m11 = -b * std::sin(th3), m12 = c * std::sin(th4);
    const double m21 = b * std::cos(th3), m22 = -c * std::cos(th4);
    const double det = m11 * m22 - m12 * m21;
    const double a3 = (rx * m22 - m12 * ry) / det;
    const double a4 = (m11 * ry - m21 * rx) / det;
    EXPECT_NEAR(s.LinkAngularAcceleration(links[1]), a3, kRelativeTol * w2 * w2) << t;
    EXPECT_NEAR(s.LinkAngularAcceleration(links[2]), a4, kRelativeTol * w2 * w2) << t;
    // Joint B above the ground line throughout (the benchmark's branch).
    EXPECT_GT(s.position_m[2].y(), 0.0);
  };
  ASSERT_TRUE(linkage_testing::FollowLinkage(scene, {0.1, 0.1, 0.1}, times, false, at));
  EXPECT_EQ(instants, 51);
}

struct GearCheck {
  double f, py, pz, dphi;
};

GearCheck EvaluateGear(const std::vector<double>& design, spec::AnalysisReport* report) {
  const spec::Scene scene = LandingGearScene();
  *report = multibody::AnalyzeLinkageScene(scene, LandingGearDesign(design));
  EXPECT_TRUE(report->ok()) << report->failure.reason;
  if (!report->ok()) return {};
  const double py = report->outputs[0].series[0].back() * 1e3;
  const double pz = report->outputs[1].series[0].back() * 1e3;
  const double dphi = report->outputs[2].series[0].back();
  const double f = std::sqrt((py - 160) * (py - 160) + (pz - 80) * (pz - 80) +
                             5000 * (dphi - 1.222) * (dphi - 1.222));
  return {f, py, pz, dphi};
}

TEST(LandingGear, InitialDesignReproducesCheckValues) {
  spec::AnalysisReport report;
  const GearCheck g = EvaluateGear({100, 110, 130, 110, 160, 155, 180, 100, -2.0}, &report);
  EXPECT_NEAR(g.f, 112.43, 0.006);
  EXPECT_NEAR(g.py, 109.04, kMmTol);
  EXPECT_NEAR(g.pz, 88.77, kMmTol);
  EXPECT_NEAR(g.dphi, -0.1899, kRadTol);
}

TEST(LandingGear, ReportOptimumReproducesCheckValues) {
  spec::AnalysisReport report;
  const GearCheck g =
      EvaluateGear({99.23, 100.0, 127.2, 139.4, 173.7, 184.8, 185.4, 104.1, -1.747}, &report);
  EXPECT_NEAR(g.f, 0.884, 0.0006);
  EXPECT_NEAR(g.py, 159.19, kMmTol);
  EXPECT_NEAR(g.pz, 80.26, kMmTol);
  EXPECT_NEAR(g.dphi, 1.2186, kRadTol);
}

TEST(KinematicAnalysis, PerformsNoTimeStepsOnlyPositionSolves) {
  spec::AnalysisReport report;
  EvaluateGear({100, 110, 130, 110, 160, 155, 180, 100, -2.0}, &report);
  EXPECT_EQ(report.formulation, spec::Formulation::kKinematic);
  EXPECT_EQ(report.counters.time_steps, 0);
  EXPECT_EQ(report.counters.rhs_evaluations, 0);
  // 2 rad in steps of at most 20 degrees: at least 6 Newton solves.
  EXPECT_GE(report.counters.position_solves, 6);
}

TEST(KinematicAnalysis, BarTooShortCannotAssembleAndSaysWhere) {
  spec::Scene scene = LandingGearScene();
  auto& m = std::get<spec::LinkageModel>(scene.model);
  m.links[1].length_m = linkage_testing::Lit(0.001);  // coupler 1 mm: the loop cannot close
  const spec::AnalysisReport report = multibody::AnalyzeLinkageScene(
      scene, LandingGearDesign({100, 110, 130, 110, 160, 155, 180, 100, -2.0}));
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.failure.kind, spec::FailureKind::kAssembly);
  EXPECT_THAT(report.failure.reason, HasSubstr("cannot assemble"));
  EXPECT_THAT(report.failure.reason, HasSubstr("t = 0 s"));
  EXPECT_THAT(report.failure.reason, HasSubstr("joint 'J"));
  EXPECT_TRUE(report.outputs.empty());
}

// A non-Grashof four-bar (crank 1, coupler 1.5, rocker 1, ground 2) driven
// counter-clockwise from 90 degrees locks when |A - O4| = b + c = 2.5, i.e.
// at crank angle acos(-0.3125) = 1.8884 rad, t = 1.8884 - pi/2 = 0.3176 s.
TEST(KinematicAnalysis, MechanismDrivenIntoLockFailsNamingTimeAndJoint) {
  using linkage_testing::At;
  using linkage_testing::Lit;
  spec::Scene scene;
  spec::LinkageModel m;
  m.joints = {{"O2", At(0, 0), true}, {"A", At(0, 1), false}, {"B", At(1.2, 1.4), false},
              {"O4", At(2, 0), true}};
  spec::Link crank{"crank", 0, 1, Lit(1.0), {}, 0, false, {}};
  spec::Link coupler{"coupler", 1, 2, Lit(1.5), {}, 0, false, {}};
  spec::Link rocker{"rocker", 3, 2, Lit(1.0), {}, 0, false, {}};
  m.links = {crank, coupler, rocker};
  m.driver.link = 0;
  m.driver.pivot_joint = 0;
  m.driver.angular_velocity_rad_per_s = Lit(1.0);
  scene.model = m;
  scene.outputs = {linkage_testing::JointOutput("B_x", 2, spec::Axis::kX)};
  scene.time_grid = {0.0, 1.0, 11};
  const spec::AnalysisReport report = multibody::AnalyzeLinkageScene(scene, {});
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.failure.kind, spec::FailureKind::kAssembly);
  EXPECT_THAT(report.failure.reason, HasSubstr("locks at t = 0.317"));
  EXPECT_THAT(report.failure.reason, HasSubstr("joint 'B'"));
}

TEST(KinematicAnalysis, MechanismWithFreedomLeftIsRejected) {
  using linkage_testing::At;
  spec::Scene scene;
  spec::LinkageModel m;  // a five-bar with one driver keeps one degree of freedom
  m.joints = {{"O1", At(0, 0), true}, {"A", At(0, 1), false}, {"B", At(1, 1.5), false},
              {"C", At(2, 1), false}, {"O5", At(2, 0), true}};
  m.links = {{"l1", 0, 1, {}, {}, 0, false, {}}, {"l2", 1, 2, {}, {}, 0, false, {}},
             {"l3", 2, 3, {}, {}, 0, false, {}}, {"l4", 4, 3, {}, {}, 0, false, {}}};
  m.driver.link = 0;
  m.driver.pivot_joint = 0;
  m.driver.angular_velocity_rad_per_s = linkage_testing::Lit(1.0);
  scene.model = m;
  scene.outputs = {linkage_testing::JointOutput("B_x", 2, spec::Axis::kX)};
  scene.time_grid = {0.0, 1.0, 2};
  const spec::AnalysisReport report = multibody::AnalyzeLinkageScene(scene, {});
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_THAT(report.failure.reason, HasSubstr("1 degree(s) of freedom"));
}

}  // namespace
}  // namespace mbopt
