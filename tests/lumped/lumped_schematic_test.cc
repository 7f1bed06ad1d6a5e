// The schematic of a lumped scene (worker/lumped/lumped_schematic.h): the
// half car of examples/vehicle, drawn from the scene alone.
#include "worker/lumped/lumped_schematic.h"

#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/io/study_io.h"

namespace mbopt::lumped {
namespace {

const spec::SceneDrawing::Body* BodyNamed(const spec::SceneDrawing& d, const std::string& name) {
  for (const spec::SceneDrawing::Body& b : d.bodies) {
    if (b.name == name) return &b;
  }
  return nullptr;
}

// The body's lowest and highest y, and its centre's x.
struct Extent {
  double bottom = 0, top = 0, centre_x = 0;
};
Extent ExtentOf(const spec::SceneDrawing& d, const spec::SceneDrawing::Body& b) {
  Extent e{1e300, -1e300, 0};
  for (const int p : b.points) {
    e.bottom = std::min(e.bottom, d.points_m[0][p].y_m);
    e.top = std::max(e.top, d.points_m[0][p].y_m);
    e.centre_x += d.points_m[0][p].x_m / static_cast<double>(b.points.size());
  }
  return e;
}

TEST(LumpedSchematic, StacksTheHalfCarAboveItsRoadInputs) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile("examples/vehicle/vehicle.scene.textproto");
  ASSERT_TRUE(scene.ok()) << scene.status();
  const spec::SceneDrawing d = LumpedSchematic(*scene, scene->DefaultParameterValues());
  ASSERT_EQ(d.failure, "");
  EXPECT_TRUE(d.schematic);
  ASSERT_EQ(d.points_m.size(), 1u);
  ASSERT_EQ(d.bodies.size(), 4u);
  const auto* seat = BodyNamed(d, "seat");
  const auto* chassis = BodyNamed(d, "chassis");
  const auto* front = BodyNamed(d, "front_axle");
  ASSERT_TRUE(seat != nullptr && chassis != nullptr && front != nullptr);
  // seat on the chassis, the chassis on the axles, the axles on the road.
  EXPECT_GT(ExtentOf(d, *seat).bottom, ExtentOf(d, *chassis).top);
  EXPECT_GT(ExtentOf(d, *chassis).bottom, ExtentOf(d, *front).top);
  EXPECT_GT(ExtentOf(d, *front).bottom, 0.0);
  // The front axle stands at its declared x (40 in) ahead of the rear one.
  EXPECT_NEAR(ExtentOf(d, *front).centre_x, 40 * 0.0254, 1e-12);
  EXPECT_LT(ExtentOf(d, *BodyNamed(d, "rear_axle")).centre_x, 0.0);
  // Every element joins two points; suspensions are springs with dampers;
  // the tyres stand on the road inputs, drawn as arrows along y.
  int springs_with_dampers = 0;
  for (const spec::SceneDrawing::Element& e : d.elements) {
    ASSERT_GE(e.a, 0);
    ASSERT_GE(e.b, 0);
    springs_with_dampers += e.spring && e.damper ? 1 : 0;
  }
  EXPECT_EQ(springs_with_dampers, static_cast<int>(d.elements.size()));
  ASSERT_EQ(d.inputs.size(), 2u);
  for (const spec::SceneDrawing::Input& in : d.inputs) {
    EXPECT_EQ(d.points_m[0][in.point].y_m, 0.0) << in.name;
    EXPECT_EQ(in.direction_y, 1.0);
  }
}

TEST(LumpedSchematic, SaysWhenTheSceneIsNotLumped) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile("examples/press/press.scene.textproto");
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_THAT(LumpedSchematic(*scene, scene->DefaultParameterValues()).failure,
              ::testing::HasSubstr("expected a lumped scene"));
}

}  // namespace
}  // namespace mbopt::lumped
