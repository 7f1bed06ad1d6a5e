// The drawing of a linkage whose analysis follows its links elastically
// (worker/multibody/linkage_geometry.h): a driven arm held still under its
// own weight is a cantilever, drawn with the Euler-Bernoulli static
// deflection; the same arm rigid is drawn undeflected; asking the analysis
// for the deflection changes none of its numbers.
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "worker/multibody/linkage_analysis.h"
#include "worker/multibody/linkage_geometry.h"

namespace mbopt::multibody {
namespace {

// A steel arm (L = 1 m, A = 1e-3 m^2 solid circular: I = A^2 / (4 pi))
// clamped to a driver that holds it horizontal (0 rad/s), loaded by
// gravity across it: a cantilever under q = rho A g. The floating-frame
// integration starts undeformed; twice critical damping at the arm's
// pinned-clamped frequency (694 rad/s) damps the cantilever mode (158 rad/s)
// at 0.46 of critical, so by t = 1 s the start-up transient has decayed by
// e^-72 and the arm rests at its static deflection.
constexpr char kArm[] = R"pb(
name: "arm"
effects {
  gravity { acceleration_m_per_s2 { x { value: 0 } y { value: -9.81 } } }
  structural_damping { ratio_of_critical: 2 }
}
linkage {
  joints { name: "O" position_m { x { value: 0 } y { value: 0 } } ground: true }
  joints { name: "T" position_m { x { value: 1 } y { value: 0 } } }
  links {
    name: "arm" joint_a: "O" joint_b: "T" length_m { value: 1 }
    section { area_m2 { value: 1e-3 } youngs_modulus_pa { value: 2e11 } density_kg_per_m3 { value: 7850 } }
    flexible { elements: 8 }
  }
  driver { link: "arm" pivot_joint: "O" start_angle_rad { value: 0 } angular_velocity_rad_per_s { value: 0 } }
}
outputs { name: "torque" drive_torque {} }
time_grid { start_s: 0 end_s: 1 points: 11 }
integrator { relative_tolerance: 1e-9 absolute_tolerance: 1e-13 }
)pb";

constexpr double kLengthM = 1.0, kAreaM2 = 1e-3, kYoungsPa = 2e11, kDensityKgPerM3 = 7850, kGravityMPerS2 = 9.81;
constexpr int kElements = 8;
// Hermite beam elements with consistent loads give a uniformly loaded
// cantilever's nodal deflections exactly; what is left is the integrator's
// error (relative tolerance 1e-9) and the transient's e^-72. Measured:
// 2e-13 of the tip deflection (0.6 mm); a billionth of it leaves room for
// another platform's round-off and still fails on a rigid drawing.
constexpr double kDeflectionTolerance = 1e-9;
// Positions of the rigid drawing are closed by Newton to 1e-11 m.
constexpr double kRigidTolerance = 1e-9;

spec::Scene Parse(const std::string& text) {
  absl::StatusOr<spec::Scene> scene = spec::io::ParseSceneText(text, "arm.scene.textproto");
  EXPECT_TRUE(scene.ok()) << scene.status();
  return scene.ok() ? *scene : spec::Scene{};
}

// w(x) = q x^2 (6 L^2 - 4 L x + x^2) / (24 E I), downwards.
double CantileverDeflection(double x_m) {
  const double q = kDensityKgPerM3 * kAreaM2 * kGravityMPerS2;
  const double ei = kYoungsPa * kAreaM2 * kAreaM2 / (4 * std::numbers::pi);
  return q * x_m * x_m * (6 * kLengthM * kLengthM - 4 * kLengthM * x_m + x_m * x_m) / (24 * ei);
}

int PointNamed(const spec::SceneDrawing& d, const std::string& name) {
  for (size_t k = 0; k < d.point_names.size(); ++k) {
    if (d.point_names[k] == name) return static_cast<int>(k);
  }
  ADD_FAILURE() << "no point named " << name;
  return 0;
}

TEST(DeflectedLinkageDrawing, ACantileverArmIsDrawnWithItsStaticDeflection) {
  const spec::SceneDrawing d = DrawLinkageScene(Parse(kArm), {});
  ASSERT_EQ(d.failure, "");
  ASSERT_EQ(d.times_s.size(), 11u);
  // The arm is its centre line through its nodes, pin to pin.
  ASSERT_EQ(d.lines.size(), 1u);
  EXPECT_EQ(d.lines[0].name, "arm");
  ASSERT_EQ(d.lines[0].points.size(), static_cast<size_t>(kElements + 1));
  EXPECT_EQ(d.lines[0].points.front(), PointNamed(d, "O"));
  EXPECT_EQ(d.lines[0].points.back(), PointNamed(d, "T"));
  EXPECT_EQ(d.bodies.size(), 0u) << "a deflected link is drawn as its line, not as a straight bar";
  const double tip = CantileverDeflection(kLengthM);
  EXPECT_NEAR(tip, 6.05e-4, 1e-6);  // q L^4 / (8 E I): the size the check is about
  const std::vector<spec::DrawingPosition>& rest = d.points_m.back();
  for (int node = 0; node <= kElements; ++node) {
    const double x = kLengthM * node / kElements;
    const spec::DrawingPosition& at = rest[static_cast<size_t>(d.lines[0].points[static_cast<size_t>(node)])];
    EXPECT_NEAR(at.y_m, -CantileverDeflection(x), kDeflectionTolerance * tip) << "node " << node;
    EXPECT_NEAR(at.x_m, x, kDeflectionTolerance * tip) << "node " << node << ": no axial load";
  }
  // At t = 0 the arm starts undeformed.
  const spec::DrawingPosition start = d.points_m.front()[static_cast<size_t>(PointNamed(d, "T"))];
  EXPECT_NEAR(start.y_m, 0.0, kDeflectionTolerance * tip);
}

TEST(DeflectedLinkageDrawing, TheArmRigidIsDrawnUndeflected) {
  std::string rigid = kArm;
  rigid.erase(rigid.find("flexible { elements: 8 }"), std::string("flexible { elements: 8 }").size());
  rigid.erase(rigid.find("structural_damping { ratio_of_critical: 2 }"),
              std::string("structural_damping { ratio_of_critical: 2 }").size());
  const spec::SceneDrawing d = DrawLinkageScene(Parse(rigid), {});
  ASSERT_EQ(d.failure, "");
  EXPECT_TRUE(d.lines.empty());
  ASSERT_EQ(d.bodies.size(), 1u);
  EXPECT_EQ(d.bodies[0].points, (std::vector<int>{PointNamed(d, "O"), PointNamed(d, "T")}));
  ASSERT_EQ(d.points_m.size(), 11u);
  for (const std::vector<spec::DrawingPosition>& at : d.points_m) {
    EXPECT_NEAR(at[static_cast<size_t>(PointNamed(d, "T"))].x_m, kLengthM, kRigidTolerance);
    EXPECT_NEAR(at[static_cast<size_t>(PointNamed(d, "T"))].y_m, 0.0, kRigidTolerance);
  }
}

// The deflection is kept only for a drawing: the analysis that keeps it
// computes the same outputs with the same work, bit for bit.
TEST(DeflectedLinkageDrawing, KeepingTheDeflectionChangesNoNumberOfTheAnalysis) {
  const spec::Scene scene = Parse(kArm);
  const spec::AnalysisReport plain = AnalyzeLinkageScene(scene, {});
  LinkageDeflection deflection;
  const spec::AnalysisReport kept = AnalyzeLinkageScene(scene, {}, nullptr, &deflection);
  ASSERT_TRUE(plain.ok()) << plain.failure.reason;
  ASSERT_TRUE(kept.ok()) << kept.failure.reason;
  EXPECT_EQ(plain.outputs[0].series, kept.outputs[0].series);
  EXPECT_EQ(plain.counters.time_steps, kept.counters.time_steps);
  EXPECT_EQ(plain.counters.rhs_evaluations, kept.counters.rhs_evaluations);
  EXPECT_EQ(plain.counters.newton_iterations, kept.counters.newton_iterations);
  EXPECT_EQ(plain.counters.position_solves, kept.counters.position_solves);
  ASSERT_EQ(deflection.node_displacement_m.size(), 11u);
  ASSERT_EQ(deflection.node_displacement_m.back().size(), 1u);
  EXPECT_EQ(deflection.node_displacement_m.back()[0].size(), static_cast<size_t>(kElements + 1));
  // The drive holds the weight of the arm: q L^2 / 2 at the root, as the
  // drawing's rest is static.
  const double q = kDensityKgPerM3 * kAreaM2 * kGravityMPerS2;
  EXPECT_NEAR(std::abs(kept.outputs[0].series[0].back()), q * kLengthM * kLengthM / 2, 1e-6 * q);
}

}  // namespace
}  // namespace mbopt::multibody
