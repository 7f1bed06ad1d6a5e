// The linkage front end of the multibody engine: what a linkage scene
// compiles to, and absurd drivers refused before any position is solved.
#include <chrono>
#include <numbers>
#include <variant>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/linkage/linkage_scenes.h"
#include "worker/multibody/linkage_analysis.h"
#include "worker/multibody/linkage_front_end.h"
#include "worker/multibody/linkage_system.h"

namespace mbopt {
namespace {

using linkage_testing::FourBarScene;
using ::testing::HasSubstr;

TEST(LinkageFrontEnd, FourBarCompilesToThreeBarsFourPinsAndOneDriver) {
  const spec::Scene scene = FourBarScene();
  const std::vector<double> areas = {1e-3, 2e-3, 3e-3};
  auto sys = multibody::ResolveLinkage(std::get<spec::LinkageModel>(scene.model), scene.effects, areas);
  ASSERT_TRUE(sys.ok()) << sys.status();
  const multibody::CompiledLinkage c = multibody::CompileLinkage(*sys);
  ASSERT_EQ(c.model.bodies.size(), 3u);
  const double lengths[3] = {linkage_testing::kCrankM, linkage_testing::kCouplerM, linkage_testing::kRockerM};
  for (int i = 0; i < 3; ++i) {
    const multibody::Body& b = c.model.bodies[static_cast<size_t>(i)];
    const double mass = 2757.0 * areas[static_cast<size_t>(i)] * lengths[i];
    EXPECT_EQ(c.link_body[static_cast<size_t>(i)], i);
    EXPECT_DOUBLE_EQ(b.mass_kg, mass) << b.name;
    EXPECT_DOUBLE_EQ(b.inertia_kg_m2, mass * lengths[i] * lengths[i] / 12.0) << b.name;
  }
  // O2-crank, A crank-coupler, B coupler-rocker, O4-rocker: each named after its pin.
  ASSERT_EQ(c.model.joints.size(), 4u);
  const char* names[4] = {"O2", "A", "B", "O4"};
  for (int j = 0; j < 4; ++j) {
    EXPECT_EQ(c.model.joints[static_cast<size_t>(j)].name, names[j]);
    EXPECT_EQ(c.model.joints[static_cast<size_t>(j)].kind, multibody::JointKind::kRevolute);
  }
  EXPECT_EQ(c.model.joints[0].a.body, multibody::kGround);
  EXPECT_EQ(c.model.joints[1].a.body, 0);
  EXPECT_EQ(c.model.joints[1].b.body, 1);
  // The crank's absolute angle runs from -pi/2 at 10 pi rad/s.
  ASSERT_EQ(c.model.drivers.size(), 1u);
  EXPECT_EQ(c.model.drivers[0].joint, 0);
  EXPECT_DOUBLE_EQ(c.model.drivers[0].profile.start, -std::numbers::pi / 2);
  EXPECT_DOUBLE_EQ(c.model.drivers[0].profile.rate, 10 * std::numbers::pi);
  EXPECT_FALSE(c.model.gravity_m_per_s2.has_value());
}

TEST(LinkageFrontEnd, RotaryInertiaAddsRhoIPerLengthToTheBar) {
  spec::Scene scene = FourBarScene();
  for (spec::Link& l : std::get<spec::LinkageModel>(scene.model).links) l.rotary_inertia = true;
  const double area = 1e-3;
  auto sys = multibody::ResolveLinkage(std::get<spec::LinkageModel>(scene.model), scene.effects, {area, area, area});
  ASSERT_TRUE(sys.ok());
  const multibody::CompiledLinkage c = multibody::CompileLinkage(*sys);
  const double l = linkage_testing::kCouplerM, mass = 2757.0 * area * l;
  EXPECT_DOUBLE_EQ(c.model.bodies[1].inertia_kg_m2,
                   mass * l * l / 12.0 + 2757.0 * area * area / (4.0 * std::numbers::pi) * l);
}

// A pin joining three bars is two revolute joints from the first bar's end.
TEST(LinkageFrontEnd, PinOfThreeBarsIsTwoRevoluteJoints) {
  using linkage_testing::At;
  using linkage_testing::Lit;
  spec::Scene scene = FourBarScene();
  auto& m = std::get<spec::LinkageModel>(scene.model);
  m.joints.push_back({"C", At(1.5, 0.8), false});
  m.joints.push_back({"O6", At(2.0, 0.0), true});
  spec::Link arm{"arm", 2, 4, {}, {}, 0, false, {}};
  spec::Link stay{"stay", 5, 4, {}, {}, 0, false, {}};
  m.links.push_back(arm);
  m.links.push_back(stay);
  auto sys = multibody::ResolveLinkage(m, scene.effects, {1e-3, 1e-3, 1e-3});
  ASSERT_TRUE(sys.ok());
  const multibody::CompiledLinkage c = multibody::CompileLinkage(*sys);
  int at_b = 0;
  for (const multibody::Joint& j : c.model.joints) at_b += j.name == "B" ? 1 : 0;
  EXPECT_EQ(at_b, 2);
  EXPECT_EQ(c.model.joints.size(), 7u);
  std::string why;
  EXPECT_EQ(multibody::LinkageDegreesOfFreedom(*sys, &why), 0) << why;
  scene.outputs = {linkage_testing::JointOutput("C_y", 4, spec::Axis::kY)};
  const spec::AnalysisReport r = multibody::AnalyzeLinkageScene(scene, {1e-3, 1e-3, 1e-3});
  ASSERT_TRUE(r.ok()) << r.failure.reason;
}

// A crank turning 1e19 times between two instants, or a grid ending at
// 1e20 s, cannot be followed: refused at once, naming the driver.
TEST(LinkageFrontEnd, DriverTurningTooFarIsRefusedBeforeAnyPositionSolve) {
  spec::Scene fast = FourBarScene();
  std::get<spec::LinkageModel>(fast.model).driver.angular_velocity_rad_per_s = linkage_testing::Lit(1e29);
  spec::Scene long_grid = FourBarScene();
  long_grid.time_grid = {0.0, 1e20, 11};
  for (const spec::Scene* scene : {&fast, &long_grid}) {
    const auto start = std::chrono::steady_clock::now();
    const spec::AnalysisReport r = multibody::AnalyzeLinkageScene(*scene, {1e-3, 1e-3, 1e-3});
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.failure.kind, spec::FailureKind::kInvalidModel);
    EXPECT_THAT(r.failure.reason, HasSubstr("the driver turns"));
    EXPECT_THAT(r.failure.reason, HasSubstr("slow the driver"));
    EXPECT_EQ(r.counters.position_solves, 1);  // the assembly at t = 0 only
    EXPECT_LT(seconds, 5.0);
  }
}

}  // namespace
}  // namespace mbopt
