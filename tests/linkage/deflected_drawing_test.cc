// The drawing of a linkage whose analysis follows its links elastically
// (worker/multibody/linkage_geometry.h): a driven arm held still under its
// own weight is a cantilever, drawn with the Euler-Bernoulli static
// deflection in the floating-frame and in the co-rotational formulation;
// the same arm rigid is drawn undeflected, and flexible with only motion
// outputs drawn rigid with a note; asking the analysis for the deflection
// changes none of its numbers.
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "spec/io/drawing_convert.h"
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

// The same arm in the co-rotational formulation, its tip's height an output
// too. Its nodes carry lumped masses (HRZ, flexible_link.h): gravity loads
// the nodes with forces only, which is the consistent load plus a moment
// -q h^2 / 12 at the tip (h = L / 8), so the nodal deflections are the
// closed form's plus that moment's, x^2 q h^2 / (24 E I). The arm is made
// 100 times stiffer (E = 2e13 Pa) so that what the co-rotational elements
// add to the linear beam, of order (w / L)^2, stays below the tolerance
// (kDeflectionTolerance, as the floating frame's). Measured: 2.9e-11 of the
// tip deflection at the tip, the integrator's error; the points' drawing in
// along the arm, 2.1e-11 m at the tip.
std::string CorotationalArm() {
  std::string text = kArm;
  text.replace(text.find("youngs_modulus_pa { value: 2e11 }"), std::string("youngs_modulus_pa { value: 2e11 }").size(),
               "youngs_modulus_pa { value: 2e13 }");
  text.replace(text.find("linkage {"), std::string("linkage {").size(),
               "linkage {\n  flexible_formulation: FLEXIBLE_FORMULATION_COROTATIONAL");
  text.replace(text.find("outputs {"), std::string("outputs {").size(),
               "outputs { name: \"tip_x\" point_position { point: \"T\" axis: AXIS_X } }\n"
               "outputs { name: \"tip_y\" point_position { point: \"T\" axis: AXIS_Y } }\noutputs {");
  return text;
}
constexpr double kCorotationalYoungsPa = 2e13;
constexpr int kShapePoints = 3;  // drawn between two nodes

// Downwards, at x along the arm: the closed form with the lumped loads' tip
// moment, and inside an element (s from its node a) less what its cubic
// shape leaves out of the uniform load's quartic, q s^2 (h - s)^2 / (24 E I).
double LumpedCantileverDeflection(double x_m) {
  const double q = kDensityKgPerM3 * kAreaM2 * kGravityMPerS2;
  const double ei = kCorotationalYoungsPa * kAreaM2 * kAreaM2 / (4 * std::numbers::pi);
  const double h = kLengthM / kElements;
  const double closed = q * x_m * x_m * (6 * kLengthM * kLengthM - 4 * kLengthM * x_m + x_m * x_m) / (24 * ei);
  const double s = x_m - h * std::floor(x_m / h + 1e-9);
  return closed + x_m * x_m * q * h * h / (24 * ei) - q * s * s * (h - s) * (h - s) / (24 * ei);
}

TEST(CorotationalLinkageDrawing, ACantileverArmIsDrawnWithItsStaticDeflection) {
  const spec::SceneDrawing d = DrawLinkageScene(Parse(CorotationalArm()), {});
  ASSERT_EQ(d.failure, "");
  ASSERT_EQ(d.times_s.size(), 11u);
  EXPECT_EQ(d.note, "");
  // The arm is its centre line pin to pin: per element its shape points,
  // then its end node.
  ASSERT_EQ(d.lines.size(), 1u);
  EXPECT_EQ(d.lines[0].name, "arm");
  const size_t drawn = static_cast<size_t>(kElements * (kShapePoints + 1) + 1);
  ASSERT_EQ(d.lines[0].points.size(), drawn);
  EXPECT_EQ(d.lines[0].points.front(), PointNamed(d, "O"));
  EXPECT_EQ(d.lines[0].points.back(), PointNamed(d, "T"));
  EXPECT_EQ(d.lines[0].points[kShapePoints + 1], PointNamed(d, "arm.node 1"));
  EXPECT_EQ(d.bodies.size(), 0u);
  const double q = kDensityKgPerM3 * kAreaM2 * kGravityMPerS2;
  const double ei = kCorotationalYoungsPa * kAreaM2 * kAreaM2 / (4 * std::numbers::pi);
  const double tip = LumpedCantileverDeflection(kLengthM);
  // q L^4 / (8 E I) and the lumped loads' 1/192 more: the size of the check.
  EXPECT_NEAR(tip, q / (8 * ei) * (1 + 1.0 / 192), 1e-15);
  EXPECT_NEAR(tip, 6.08e-6, 1e-8);
  // Bending an inextensible arm draws its points in along it by the
  // second-order (1/2) integral of w'^2, less than (1/2) w'(L)^2 L.
  const double tip_slope = q * kLengthM * kLengthM * kLengthM / (6 * ei);
  const double shortening = 0.5 * tip_slope * tip_slope * kLengthM;
  const std::vector<spec::DrawingPosition>& rest = d.points_m.back();
  for (size_t k = 0; k < drawn; ++k) {
    const double x = kLengthM * static_cast<double>(k) / (drawn - 1);
    const spec::DrawingPosition& at = rest[static_cast<size_t>(d.lines[0].points[k])];
    EXPECT_NEAR(at.y_m, -LumpedCantileverDeflection(x), kDeflectionTolerance * tip) << "point " << k;
    EXPECT_NEAR(at.x_m, x, shortening) << "point " << k;
  }
  const spec::DrawingPosition start = d.points_m.front()[static_cast<size_t>(PointNamed(d, "T"))];
  EXPECT_NEAR(start.y_m, 0.0, kDeflectionTolerance * tip);
}

// The drawn pins and nodes are the analysis' own coordinates, bit for bit:
// the tip as its outputs give it, every node as its state holds it.
TEST(CorotationalLinkageDrawing, TheNodesAreTheAnalysisOwn) {
  const spec::Scene scene = Parse(CorotationalArm());
  LinkageDeflection deflection;
  const spec::AnalysisReport report = AnalyzeLinkageScene(scene, {}, nullptr, &deflection);
  ASSERT_TRUE(report.ok()) << report.failure.reason;
  const spec::SceneDrawing d = DrawLinkageScene(scene, {});
  ASSERT_EQ(d.points_m.size(), report.times_s.size());
  ASSERT_EQ(deflection.corotational_q.size(), report.times_s.size());
  EXPECT_EQ(deflection.rigid_states.size(), 0u);
  for (size_t i = 0; i < d.points_m.size(); ++i) {
    EXPECT_EQ(d.times_s[i], report.times_s[i]);
    const spec::DrawingPosition& t = d.points_m[i][static_cast<size_t>(PointNamed(d, "T"))];
    EXPECT_EQ(t.x_m, report.outputs[0].series[0][i]) << "instant " << i;
    EXPECT_EQ(t.y_m, report.outputs[1].series[0][i]) << "instant " << i;
    // The nodes are bodies 0..8 of the compiled model, root to tip.
    const Eigen::VectorXd& q = deflection.corotational_q[i];
    for (int node = 1; node <= kElements; ++node) {
      const std::string name = node == kElements ? "T" : "arm.node " + std::to_string(node);
      const spec::DrawingPosition& at = d.points_m[i][static_cast<size_t>(PointNamed(d, name))];
      EXPECT_EQ(at.x_m, q[3 * node]) << name << " at instant " << i;
      EXPECT_EQ(at.y_m, q[3 * node + 1]) << name << " at instant " << i;
    }
  }
}

TEST(CorotationalLinkageDrawing, KeepingTheMotionChangesNoNumberOfTheAnalysis) {
  const spec::Scene scene = Parse(CorotationalArm());
  const spec::AnalysisReport plain = AnalyzeLinkageScene(scene, {});
  LinkageDeflection deflection;
  const spec::AnalysisReport kept = AnalyzeLinkageScene(scene, {}, nullptr, &deflection);
  ASSERT_TRUE(plain.ok()) << plain.failure.reason;
  ASSERT_TRUE(kept.ok()) << kept.failure.reason;
  EXPECT_EQ(deflection.corotational_q.size(), 11u);
  for (size_t k = 0; k < plain.outputs.size(); ++k) EXPECT_EQ(plain.outputs[k].series, kept.outputs[k].series);
  EXPECT_EQ(plain.counters.time_steps, kept.counters.time_steps);
  EXPECT_EQ(plain.counters.rhs_evaluations, kept.counters.rhs_evaluations);
  EXPECT_EQ(plain.counters.newton_iterations, kept.counters.newton_iterations);
}

// Flexible, but every output a position: the analysis is kinematic (the
// cheapest formulation) and computes no deflection, so the arm is drawn
// rigid, as the analysis moves it, and the drawing says why.
TEST(KinematicLinkageDrawing, AFlexibleArmWithMotionOutputsOnlyIsDrawnRigidWithANote) {
  std::string text = kArm;
  text.replace(text.find("outputs { name: \"torque\" drive_torque {} }"),
               std::string("outputs { name: \"torque\" drive_torque {} }").size(),
               "outputs { name: \"tip_y\" point_position { point: \"T\" axis: AXIS_Y } }");
  for (const bool corotational : {false, true}) {
    std::string scene_text = text;
    if (corotational) {
      scene_text.replace(scene_text.find("linkage {"), std::string("linkage {").size(),
                         "linkage {\n  flexible_formulation: FLEXIBLE_FORMULATION_COROTATIONAL");
    }
    const spec::Scene scene = Parse(scene_text);
    const spec::AnalysisReport report = AnalyzeLinkageScene(scene, {});
    ASSERT_TRUE(report.ok()) << report.failure.reason;
    EXPECT_EQ(report.formulation, spec::Formulation::kKinematic);
    const spec::SceneDrawing d = DrawLinkageScene(scene, {});
    ASSERT_EQ(d.failure, "");
    EXPECT_TRUE(d.lines.empty()) << "corotational " << corotational;
    ASSERT_EQ(d.bodies.size(), 1u);
    EXPECT_EQ(d.bodies[0].points, (std::vector<int>{PointNamed(d, "O"), PointNamed(d, "T")}));
    ASSERT_EQ(d.points_m.size(), 11u);
    for (size_t i = 0; i < d.points_m.size(); ++i) {
      EXPECT_NEAR(d.points_m[i][static_cast<size_t>(PointNamed(d, "T"))].y_m, report.outputs[0].series[0][i],
                  kRigidTolerance);
    }
    EXPECT_NE(d.note.find("drawn rigid"), std::string::npos) << d.note;
    EXPECT_NE(d.note.find("kinematic"), std::string::npos) << d.note;
    // The note travels with the drawing file.
    absl::StatusOr<spec::SceneDrawing> read = spec::io::DrawingFromProto(spec::io::DrawingToProto(d));
    ASSERT_TRUE(read.ok()) << read.status();
    EXPECT_EQ(read->note, d.note);
  }
  // Rigid links need no note: there is no deflection to leave out.
  std::string rigid = text;
  rigid.erase(rigid.find("flexible { elements: 8 }"), std::string("flexible { elements: 8 }").size());
  EXPECT_EQ(DrawLinkageScene(Parse(rigid), {}).note, "");
}

}  // namespace
}  // namespace mbopt::multibody
