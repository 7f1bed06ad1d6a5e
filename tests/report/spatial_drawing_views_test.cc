// Spatial drawings in the report's views (client/report/drawing_views.h)
// and as pictures (mechanism_drawing.h): a known scene drawn by the worker,
// through its file schema, projected into each view at the closed-form
// places of its markers; an axis seen end-on shrinks; the sheet of four
// views is well formed and animated; the file schema keeps the third
// coordinate and refuses a drawing that lacks it.
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "client/report/drawing_views.h"
#include "client/report/mechanism_drawing.h"
#include "spec/io/drawing_convert.h"
#include "spec/io/study_io.h"
#include "tests/report/markup_checker.h"
#include "tests/spatial/tilted_crank_scene.h"
#include "worker/engine/scene_drawing.h"

namespace mbopt::report {
namespace {

using ::testing::HasSubstr;

// Kinematic positions are closed to 1e-12 m; a view only rotates them.
constexpr double kPositionTolerance = 1e-9;
// Views are built from 1/sqrt(2), 1/sqrt(3), 1/sqrt(6): exact to round-off.
constexpr double kUnitTolerance = 1e-15;

const DrawingView& ViewLabelled(const std::string& start) {
  for (const DrawingView& v : SpatialDrawingViews()) {
    if (v.label.rfind(start, 0) == 0) return v;
  }
  ADD_FAILURE() << "no view " << start;
  return SpatialDrawingViews().front();
}

int PointNamed(const spec::SceneDrawing& d, const std::string& name) {
  for (size_t k = 0; k < d.point_names.size(); ++k) {
    if (d.point_names[k] == name) return static_cast<int>(k);
  }
  ADD_FAILURE() << "no point named " << name;
  return 0;
}

DrawingLayer LayerOf(const spec::SceneDrawing& d) {
  DrawingLayer layer;
  layer.drawing = &d;
  return layer;
}

spec::SceneDrawing TiltedCrankFromItsFile() {
  absl::StatusOr<spec::Scene> scene =
      spec::io::ParseSceneText(mbopt::testing::kTiltedCrankScene, "tilted_crank.scene.textproto");
  EXPECT_TRUE(scene.ok()) << scene.status();
  absl::StatusOr<spec::SceneDrawing> drawn = engine::DrawScene(*scene, scene->DefaultParameterValues());
  EXPECT_TRUE(drawn.ok()) << drawn.status();
  absl::StatusOr<spec::SceneDrawing> read = spec::io::DrawingFromProto(spec::io::DrawingToProto(*drawn));
  EXPECT_TRUE(read.ok()) << read.status();
  return *read;
}

TEST(SpatialDrawingViews, AreRightHandedOrthonormalTriples) {
  ASSERT_EQ(SpatialDrawingViews().size(), 4u);
  for (const DrawingView& v : SpatialDrawingViews()) {
    const std::array<double, 3>&r = v.right, &u = v.up, &t = v.toward;
    EXPECT_NEAR(r[0] * r[0] + r[1] * r[1] + r[2] * r[2], 1.0, kUnitTolerance) << v.label;
    EXPECT_NEAR(u[0] * u[0] + u[1] * u[1] + u[2] * u[2], 1.0, kUnitTolerance) << v.label;
    EXPECT_NEAR(r[0] * u[0] + r[1] * u[1] + r[2] * u[2], 0.0, kUnitTolerance) << v.label;
    EXPECT_NEAR(r[1] * u[2] - r[2] * u[1], t[0], kUnitTolerance) << v.label;
    EXPECT_NEAR(r[2] * u[0] - r[0] * u[2], t[1], kUnitTolerance) << v.label;
    EXPECT_NEAR(r[0] * u[1] - r[1] * u[0], t[2], kUnitTolerance) << v.label;
  }
}

// The tilted crank's pin (tests/spatial/tilted_crank_scene.h) at
// t = 0.25 s and 0.5 s, in each view: front (x, z), top (x, y), right side
// (y, z), isometric (right and up of the view looking along -(1, 1, 1)).
TEST(SpatialDrawingViews, ProjectedMarkersSitAtTheirClosedFormPlaces) {
  const spec::SceneDrawing d = TiltedCrankFromItsFile();
  ASSERT_EQ(d.failure, "");
  ASSERT_TRUE(d.spatial);
  const int pin = PointNamed(d, "crank.pin");
  const double h = 1.0 / std::sqrt(2.0);
  const spec::SceneDrawing front = InView(d, ViewLabelled("front")), top = InView(d, ViewLabelled("top")),
                           side = InView(d, ViewLabelled("right side")), iso = InView(d, ViewLabelled("isometric"));
  for (const size_t i : {size_t{1}, size_t{2}}) {
    const double t = d.times_s[i], theta = std::numbers::pi * t;
    const double x = 0.2 * std::cos(theta), y = 0.2 * h * std::sin(theta), z = 0.1 + 0.2 * h * std::sin(theta);
    const auto at = [&](const spec::SceneDrawing& view) { return view.points_m[i][static_cast<size_t>(pin)]; };
    EXPECT_NEAR(at(front).x_m, x, kPositionTolerance) << "t = " << t;
    EXPECT_NEAR(at(front).y_m, z, kPositionTolerance) << "t = " << t;
    EXPECT_NEAR(at(front).z_m, -y, kPositionTolerance) << "seen from -y: nearer is smaller y";
    EXPECT_NEAR(at(top).x_m, x, kPositionTolerance) << "t = " << t;
    EXPECT_NEAR(at(top).y_m, y, kPositionTolerance) << "t = " << t;
    EXPECT_NEAR(at(side).x_m, y, kPositionTolerance) << "t = " << t;
    EXPECT_NEAR(at(side).y_m, z, kPositionTolerance) << "t = " << t;
    EXPECT_NEAR(at(iso).x_m, (y - x) / std::sqrt(2.0), kPositionTolerance) << "t = " << t;
    EXPECT_NEAR(at(iso).y_m, (2 * z - x - y) / std::sqrt(6.0), kPositionTolerance) << "t = " << t;
    // The data keep world axes: only the view turned them.
    EXPECT_NEAR(d.points_m[i][static_cast<size_t>(pin)].z_m, z, kPositionTolerance);
  }
}

// The bearing's axis n = (0, -1, 1) / sqrt(2) in each view (right, up,
// toward the viewer): the right side view (seen from +x) has it in the
// picture's plane at full length; the front and top views see it
// foreshortened to 1/sqrt(2) of it, leaning toward the viewer.
TEST(SpatialDrawingViews, JointAxesTurnWithTheView) {
  const spec::SceneDrawing d = TiltedCrankFromItsFile();
  const double h = 1.0 / std::sqrt(2.0);
  for (const auto& [label, right, up, toward] :
       std::vector<std::tuple<std::string, double, double, double>>{
           {"front", 0.0, h, h}, {"top", 0.0, -h, h}, {"right side", -h, h, 0.0}}) {
    const spec::SceneDrawing viewed = InView(d, ViewLabelled(label));
    for (const spec::DrawingDirection& a : viewed.joints[0].axis_directions) {
      EXPECT_NEAR(a.x, right, kPositionTolerance) << label;
      EXPECT_NEAR(a.y, up, kPositionTolerance) << label;
      EXPECT_NEAR(a.z, toward, kPositionTolerance) << label;
    }
  }
}

// One revolute joint whose axis is world z: end-on in the top view (no
// centre line there), in the picture's plane in the front and side views,
// foreshortened in the isometric one.
TEST(SpatialDrawingViews, AnAxisSeenEndOnHasNoCentreLine) {
  spec::SceneDrawing d;
  d.scene_name = "turntable";
  d.spatial = true;
  const int hub = d.AddPoint("hub"), rim = d.AddPoint("rim");
  d.bodies.push_back({"table", {hub, rim}});
  spec::SceneDrawing::Joint pin;
  pin.name = "spindle";
  pin.kind = spec::SceneDrawing::JointKind::kPin;
  pin.point = hub;
  d.joints.push_back(pin);
  d.times_s = {0.0};
  d.points_m = {{{0, 0, 0}, {0.3, 0.2, 0.1}}};
  d.joints[0].axis_directions = {{0, 0, 1}};
  const std::string html = MechanismFigureHtml({LayerOf(d)}, "turntable");
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"view\""), 4);
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"joint\""), 4) << "one per view";
  EXPECT_EQ(testing::CountOccurrences(html, "class=\"axis\""), 3) << "not in the top view";
  d.joints[0].axis_directions = {{1, 0, 0}};  // along x: end-on in the side view only
  EXPECT_EQ(testing::CountOccurrences(MechanismFigureHtml({LayerOf(d)}, "turntable"), "class=\"axis\""), 3);
  d.joints[0].axis_directions = {{0, 1, 0}};  // along y: end-on in the front view only
  EXPECT_EQ(testing::CountOccurrences(MechanismFigureHtml({LayerOf(d)}, "turntable"), "class=\"axis\""), 3);
}

TEST(SpatialDrawingViews, SuspensionPageIsAWellFormedAnimatedSheetOfFourViews) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile("examples/suspension/suspension.scene.textproto");
  ASSERT_TRUE(scene.ok()) << scene.status();
  absl::StatusOr<spec::SceneDrawing> drawn = engine::DrawScene(*scene, scene->DefaultParameterValues());
  ASSERT_TRUE(drawn.ok()) << drawn.status();
  ASSERT_EQ(drawn->failure, "");
  absl::StatusOr<spec::SceneDrawing> read = spec::io::DrawingFromProto(spec::io::DrawingToProto(*drawn));
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->points_m.size(), 33u);
  EXPECT_EQ(read->points_m.back().back().z_m, drawn->points_m.back().back().z_m);  // bit for bit
  EXPECT_EQ(read->joints.size(), drawn->joints.size());
  for (size_t j = 0; j < read->joints.size(); ++j) {
    EXPECT_EQ(read->joints[j].kind, drawn->joints[j].kind);
    ASSERT_EQ(read->joints[j].axis_directions.size(), drawn->joints[j].axis_directions.size());
    ASSERT_EQ(read->joints[j].second_axis_directions.size(), drawn->joints[j].second_axis_directions.size());
  }
  const std::string html = SceneDrawingPageHtml(*read, "examples/suspension/suspension.scene.textproto");
  EXPECT_EQ(testing::CheckMarkup(html, false), "");
  const std::vector<std::string> svgs = testing::SvgFragments(html);
  ASSERT_EQ(svgs.size(), 1u);
  EXPECT_EQ(testing::CheckMarkup(svgs[0], true), "");
  EXPECT_THAT(html, ::testing::Not(HasSubstr("http")));
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"frame\""), 33);
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"view\""), 4);
  EXPECT_EQ(testing::CountOccurrences(html, "<input type=\"range\""), 1);
  // Every frame shows every body in every view.
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"body\""), 33 * 4 * static_cast<int>(read->bodies.size()));
  for (const char* label : {"top: x-y", "front: x-z", "right side: y-z", "isometric"}) {
    EXPECT_THAT(html, HasSubstr(label));
  }
  EXPECT_THAT(html, HasSubstr("class=\"ball\""));  // spherical joints
  EXPECT_THAT(html, HasSubstr("class=\"arm\""));   // the universal joint's cross
  EXPECT_THAT(html, HasSubstr("class=\"plane\""));  // the tyre on the pad
}

TEST(SpatialDrawingFile, RefusesASpatialInstantWithoutItsThirdCoordinate) {
  spec::SceneDrawing d;
  d.scene_name = "flat";
  d.spatial = true;
  d.AddPoint("only");
  d.times_s = {0.0};
  d.points_m = {{{0.0, 0.0, 1.0}}};
  v1::SceneDrawing message = spec::io::DrawingToProto(d);
  ASSERT_EQ(message.instants(0).z_m_size(), 1);
  message.mutable_instants(0)->clear_z_m();
  absl::StatusOr<spec::SceneDrawing> read = spec::io::DrawingFromProto(message);
  ASSERT_FALSE(read.ok());
  EXPECT_THAT(read.status().message(), HasSubstr("instants[0].z_m has 0 values, expected 1"));
  // A joint's axes, one per instant or none.
  message = spec::io::DrawingToProto(d);
  v1::DrawingJoint* joint = message.add_joints();
  joint->set_kind(v1::DrawingJoint::KIND_CYLINDRICAL);
  joint->add_axis_directions();
  joint->add_axis_directions();
  read = spec::io::DrawingFromProto(message);
  ASSERT_FALSE(read.ok());
  EXPECT_THAT(read.status().message(), HasSubstr("joints[0].axis_directions has 2 values, expected 1"));
}

}  // namespace
}  // namespace mbopt::report
