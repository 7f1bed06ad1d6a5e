// The drawing of spatial scenes (worker/spatial/spatial_drawing.h) in world
// axes: markers against closed-form positions, joint axes and a load that
// turns with its body along their world directions, the parts of the
// examples' scenes; a dynamic example drawn on the explicit path as on IDAS.
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/spatial/scene_text_testing.h"
#include "tests/spatial/tilted_crank_scene.h"
#include "tests/testing/drawing_agreement.h"
#include "tests/testing/file_text.h"
#include "worker/spatial/spatial_drawing.h"

namespace mbopt::spatial {
namespace {

using Kind = spec::SceneDrawing::JointKind;

// Kinematic positions are closed by Newton to 1e-12 (SpatialAssemblyOptions);
// a thousand times that covers the round-off of coordinates of order 1 m.
constexpr double kPositionTolerance = 1e-9;
// Directions are rotated unit vectors of the same coordinates.
constexpr double kDirectionTolerance = 1e-9;

int PointNamed(const spec::SceneDrawing& d, const std::string& name) {
  for (size_t k = 0; k < d.point_names.size(); ++k) {
    if (d.point_names[k] == name) return static_cast<int>(k);
  }
  ADD_FAILURE() << "no point named " << name;
  return 0;
}

const spec::SceneDrawing::Joint& JointNamed(const spec::SceneDrawing& d, const std::string& name) {
  for (const spec::SceneDrawing::Joint& j : d.joints) {
    if (j.name == name) return j;
  }
  ADD_FAILURE() << "no joint named " << name;
  static const spec::SceneDrawing::Joint none;
  return none;
}

TEST(SpatialDrawing, MarkersFollowTheTiltedCranksClosedFormInWorldAxes) {
  const spec::Scene scene = scene_text::Load(testing::kTiltedCrankScene, "tilted_crank.scene.textproto");
  const spec::SceneDrawing d = DrawSpatialScene(scene, scene.DefaultParameterValues());
  ASSERT_EQ(d.failure, "");
  EXPECT_TRUE(d.spatial);
  ASSERT_EQ(d.times_s.size(), 5u);
  const int pin = PointNamed(d, "crank.pin"), block = PointNamed(d, "block.slot"), axis = PointNamed(d, "axis");
  const double h = 1.0 / std::sqrt(2.0);
  // Every instant of the grid: an eighth of a turn apart, from 0 to a half.
  for (size_t i = 0; i < d.times_s.size(); ++i) {
    const double t = d.times_s[i], theta = std::numbers::pi * t, s = 0.05 + 0.1 * t;
    const spec::DrawingPosition& p = d.points_m[i][static_cast<size_t>(pin)];
    EXPECT_NEAR(p.x_m, 0.2 * std::cos(theta), kPositionTolerance) << "t = " << t;
    EXPECT_NEAR(p.y_m, 0.2 * h * std::sin(theta), kPositionTolerance) << "t = " << t;
    EXPECT_NEAR(p.z_m, 0.1 + 0.2 * h * std::sin(theta), kPositionTolerance) << "t = " << t;
    const spec::DrawingPosition& b = d.points_m[i][static_cast<size_t>(block)];
    EXPECT_NEAR(b.x_m, s * std::cos(theta), kPositionTolerance) << "t = " << t;
    EXPECT_NEAR(b.y_m, s * h * std::sin(theta), kPositionTolerance) << "t = " << t;
    EXPECT_NEAR(b.z_m, 0.1 + s * h * std::sin(theta), kPositionTolerance) << "t = " << t;
    const spec::DrawingPosition& a = d.points_m[i][static_cast<size_t>(axis)];
    EXPECT_EQ(a.z_m, 0.1);  // ground stays put
  }
  EXPECT_THAT(d.ground_points, ::testing::ElementsAre(axis));
  ASSERT_EQ(d.bodies.size(), 2u);
  EXPECT_THAT(d.bodies[0].points, ::testing::ElementsAre(PointNamed(d, "crank.hub"), pin));
  EXPECT_THAT(d.bodies[1].points, ::testing::ElementsAre(block));
}

TEST(SpatialDrawing, JointAxesAndABodyFixedForceAlongTheirWorldDirections) {
  const spec::Scene scene = scene_text::Load(testing::kTiltedCrankScene, "tilted_crank.scene.textproto");
  const spec::SceneDrawing d = DrawSpatialScene(scene, scene.DefaultParameterValues());
  ASSERT_EQ(d.failure, "");
  const double h = 1.0 / std::sqrt(2.0);
  const spec::SceneDrawing::Joint& bearing = JointNamed(d, "bearing");
  const spec::SceneDrawing::Joint& rail = JointNamed(d, "rail");
  EXPECT_EQ(bearing.kind, Kind::kPin);
  EXPECT_EQ(rail.kind, Kind::kSlider);
  EXPECT_EQ(bearing.point, PointNamed(d, "crank.hub"));
  EXPECT_EQ(rail.point, PointNamed(d, "block.slot"));
  ASSERT_EQ(bearing.axis_directions.size(), d.times_s.size());
  ASSERT_EQ(rail.axis_directions.size(), d.times_s.size());
  EXPECT_TRUE(bearing.second_axis_directions.empty());
  ASSERT_EQ(d.loads.size(), 1u);
  const spec::SceneDrawing::Load& push = d.loads[0];
  EXPECT_EQ(push.kind, spec::SceneDrawing::LoadKind::kForce);
  EXPECT_EQ(push.point, PointNamed(d, "block.slot"));
  ASSERT_EQ(push.directions.size(), d.times_s.size());
  for (size_t i = 0; i < d.times_s.size(); ++i) {
    const double theta = std::numbers::pi * d.times_s[i];
    // The bearing's axis is the ground's: n = (0, -1, 1) / sqrt(2) always.
    EXPECT_NEAR(bearing.axis_directions[i].x, 0.0, kDirectionTolerance);
    EXPECT_NEAR(bearing.axis_directions[i].y, -h, kDirectionTolerance);
    EXPECT_NEAR(bearing.axis_directions[i].z, h, kDirectionTolerance);
    // The rail turns with the crank.
    EXPECT_NEAR(rail.axis_directions[i].x, std::cos(theta), kDirectionTolerance) << "t = " << d.times_s[i];
    EXPECT_NEAR(rail.axis_directions[i].y, h * std::sin(theta), kDirectionTolerance) << "t = " << d.times_s[i];
    EXPECT_NEAR(rail.axis_directions[i].z, h * std::sin(theta), kDirectionTolerance) << "t = " << d.times_s[i];
    EXPECT_NEAR(push.directions[i].x, -h * std::sin(theta), kDirectionTolerance) << "t = " << d.times_s[i];
    EXPECT_NEAR(push.directions[i].y, -(1 - std::cos(theta)) / 2, kDirectionTolerance) << "t = " << d.times_s[i];
    EXPECT_NEAR(push.directions[i].z, (1 + std::cos(theta)) / 2, kDirectionTolerance) << "t = " << d.times_s[i];
  }
}

// examples/suspension: every joint kind it uses with its symbol, the
// universal joint's two arms, the pad's slide along world z, the travel
// from -80 mm to +80 mm at the tyre's contact point.
TEST(SpatialDrawing, SuspensionExampleHasItsJointsAndFollowsTheTravel) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile("examples/suspension/suspension.scene.textproto");
  ASSERT_TRUE(scene.ok()) << scene.status();
  const spec::SceneDrawing d = DrawSpatialScene(*scene, scene->DefaultParameterValues());
  ASSERT_EQ(d.failure, "");
  ASSERT_EQ(d.times_s.size(), 33u);
  int revolute = 0, spherical = 0, universal = 0, prismatic = 0, on_plane = 0;
  for (const spec::SceneDrawing::Joint& j : d.joints) {
    revolute += j.kind == Kind::kPin;
    spherical += j.kind == Kind::kSpherical;
    prismatic += j.kind == Kind::kSlider;
    on_plane += j.kind == Kind::kPointOnPlane;
    if (j.kind == Kind::kSpherical) {
      EXPECT_TRUE(j.axis_directions.empty()) << j.name;
    }
    if (j.kind != Kind::kUniversal) continue;
    ++universal;
    ASSERT_EQ(j.axis_directions.size(), d.times_s.size());
    ASSERT_EQ(j.second_axis_directions.size(), d.times_s.size());
    for (size_t i = 0; i < d.times_s.size(); ++i) {
      // The cross's arms stay at right angles (the joint's own equation).
      const spec::DrawingDirection &u = j.axis_directions[i], &v = j.second_axis_directions[i];
      EXPECT_NEAR(u.x * v.x + u.y * v.y + u.z * v.z, 0.0, kDirectionTolerance);
    }
  }
  EXPECT_EQ(revolute, 2);
  EXPECT_EQ(spherical, 3);
  EXPECT_EQ(universal, 1);
  EXPECT_EQ(prismatic, 1);
  EXPECT_EQ(on_plane, 1);
  for (const spec::SceneDrawing::Joint& j : d.joints) {
    if (j.kind != Kind::kSlider) continue;
    for (const spec::DrawingDirection& u : j.axis_directions) EXPECT_NEAR(u.z, 1.0, kDirectionTolerance);
  }
}

TEST(SpatialDrawing, AMechanismThatCannotAssembleIsDrawnAsDeclaredWithItsReason) {
  // The block's slot cannot reach a rail 1 m away across a fixed joint.
  const spec::Scene scene = scene_text::Load(R"pb(
    name: "open"
    spatial {
      ground_markers { name: "here" }
      ground_markers { name: "there" position_m { x { value: 1 } } }
      bodies {
        name: "block" mass_kg { value: 1 }
        principal_inertia { moments_kg_m2 { x { value: 0.01 } y { value: 0.01 } z { value: 0.01 } } }
        markers { name: "a" }
        markers { name: "b" position_m { x { value: 0.1 } } }
      }
      joints { name: "weld" kind: SPATIAL_JOINT_FIXED a: "ground.here" b: "block.a" }
      joints { name: "ball" kind: SPATIAL_JOINT_SPHERICAL a: "ground.there" b: "block.b" }
    }
    time_grid { start_s: 0 end_s: 1 points: 3 }
  )pb",
                                             "open.scene.textproto");
  const spec::SceneDrawing d = DrawSpatialScene(scene, scene.DefaultParameterValues());
  EXPECT_THAT(d.failure, ::testing::HasSubstr("does not assemble"));
  ASSERT_EQ(d.points_m.size(), 1u);
  EXPECT_EQ(d.points_m[0][static_cast<size_t>(PointNamed(d, "block.b"))].x_m, 0.1);
}

// examples/spatial's governor with `integrator { method: EXPLICIT_RUNGE_KUTTA }`
// draws the frames the default path (IDAS) draws: the same instants, every
// point where IDAS puts it to the paths' integration error. The explicit
// path must have run (its round-off is not IDAS's) and the flyweight must
// have moved, so a drawing that repeated the start, lost frames or took the
// default path would fail.
TEST(SpatialDrawing, TheExplicitPathDrawsTheFramesOfTheDefaultPath) {
  const std::string text = mbopt::testing::FileText("examples/spatial/governor.scene.textproto");
  const std::string block = "integrator {";
  ASSERT_NE(text.find(block), std::string::npos);
  std::string explicit_text = text;
  explicit_text.insert(explicit_text.find(block) + block.size(), " method: EXPLICIT_RUNGE_KUTTA");
  const spec::Scene idas_scene = scene_text::Load(text, "governor.scene.textproto");
  const spec::Scene explicit_scene = scene_text::Load(explicit_text, "governor_explicit.scene.textproto");
  const spec::SceneDrawing idas = DrawSpatialScene(idas_scene, idas_scene.DefaultParameterValues());
  const spec::SceneDrawing erk = DrawSpatialScene(explicit_scene, explicit_scene.DefaultParameterValues());
  ASSERT_EQ(idas.failure, "");
  ASSERT_EQ(erk.failure, "");
  ASSERT_EQ(idas.times_s.size(), 61u);
  // The example integrates at rtol 1e-7, atol 1e-8 over 3 s: the paths'
  // positions differ by 2.6e-7 m at most (measured), each path's own error
  // being of that order on coordinates of 0.1 to 0.4 m. The flyweight
  // swings round with the spindle (0.22 m).
  constexpr double kPathAgreement = 2e-6;  // m
  mbopt::testing::ExpectTheFramesOfTheDefaultPath(idas, erk, kPathAgreement, 0.1, "governor");
}

}  // namespace
}  // namespace mbopt::spatial
