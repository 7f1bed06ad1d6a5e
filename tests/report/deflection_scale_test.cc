// The flexible links' deflection magnified for the eye
// (client/report/deflection_scale.h), on a synthetic drawing: each centre
// line's inner points moved off its chord by the scale, its ends and every
// other point where they were, the page saying so; scale 1 changes nothing.
#include "client/report/deflection_scale.h"

#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "client/report/mechanism_drawing.h"

namespace mbopt::report {
namespace {

using ::testing::HasSubstr;

// A link O-B of 1 m with two inner nodes, bent off its chord by
// micrometres, and a bar O-C; at the second instant B has moved.
spec::SceneDrawing BentLink() {
  spec::SceneDrawing d;
  d.scene_name = "bent";
  const int o = d.AddPoint("O"), b = d.AddPoint("B"), c = d.AddPoint("C");
  const int n1 = d.AddPoint("link.node 1"), n2 = d.AddPoint("link.node 2");
  d.bodies.push_back({"bar", {o, c}});
  d.lines.push_back({"link", {o, n1, n2, b}});
  d.times_s = {0.0, 1.0};
  d.points_m.push_back({{0, 0}, {1, 0}, {0, 1}, {1.0 / 3, 1e-5}, {2.0 / 3, 3e-5}});
  d.points_m.push_back({{0, 0}, {1, 0.6}, {0, 1}, {1.0 / 3 + 2e-6, 0.2 - 1e-5}, {2.0 / 3, 0.4}});
  return d;
}

TEST(DeflectionScale, MagnifiesEachInnerPointsOffsetFromItsChord) {
  const spec::SceneDrawing drawn = BentLink();
  const spec::SceneDrawing d = MagnifyDeflection(drawn, 1000);
  ASSERT_EQ(d.points_m.size(), 2u);
  constexpr double kTol = 1e-12;
  EXPECT_NEAR(d.points_m[0][3].x_m, 1.0 / 3, kTol);
  EXPECT_NEAR(d.points_m[0][3].y_m, 1e-2, kTol);
  EXPECT_NEAR(d.points_m[0][4].x_m, 2.0 / 3, kTol);
  EXPECT_NEAR(d.points_m[0][4].y_m, 3e-2, kTol);
  // The chord turns with B: the offsets are taken from it.
  EXPECT_NEAR(d.points_m[1][3].x_m, 1.0 / 3 + 2e-3, kTol);
  EXPECT_NEAR(d.points_m[1][3].y_m, 0.2 - 1e-2, kTol);
  EXPECT_NEAR(d.points_m[1][4].x_m, 2.0 / 3, kTol);
  EXPECT_NEAR(d.points_m[1][4].y_m, 0.4, kTol);
  // The line's ends and the other points stay where they were drawn.
  for (size_t i = 0; i < 2; ++i) {
    for (const size_t p : {0u, 1u, 2u}) {
      EXPECT_EQ(d.points_m[i][p].x_m, drawn.points_m[i][p].x_m);
      EXPECT_EQ(d.points_m[i][p].y_m, drawn.points_m[i][p].y_m);
    }
  }
  EXPECT_THAT(d.note, HasSubstr("drawn 1000 times its size"));
  EXPECT_THAT(SceneDrawingPageHtml(d, "bent.scene.textproto"),
              HasSubstr("the flexible links&#39; deflection is drawn 1000 times its size"));
}

TEST(DeflectionScale, KeepsANoteTheDrawingHad) {
  spec::SceneDrawing drawn = BentLink();
  drawn.note = "something the reader must know";
  const spec::SceneDrawing d = MagnifyDeflection(drawn, 50);
  EXPECT_THAT(d.note, HasSubstr("something the reader must know; the flexible links' deflection is drawn 50 times"));
}

TEST(DeflectionScale, ScaleOneChangesNothing) {
  const spec::SceneDrawing drawn = BentLink();
  const spec::SceneDrawing d = MagnifyDeflection(drawn, 1.0);
  EXPECT_EQ(d.note, "");
  for (size_t i = 0; i < 2; ++i) {
    for (size_t p = 0; p < drawn.points_m[i].size(); ++p) {
      EXPECT_EQ(d.points_m[i][p].x_m, drawn.points_m[i][p].x_m);
      EXPECT_EQ(d.points_m[i][p].y_m, drawn.points_m[i][p].y_m);
    }
  }
}

}  // namespace
}  // namespace mbopt::report
