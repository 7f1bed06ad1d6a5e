// The examples' scenes drawn end to end as `mbopt draw` does: the worker's
// drawing (worker/engine/scene_drawing.h) through its file schema
// (spec/io/drawing_convert.h) to the page (client/report/mechanism_drawing.h),
// which must be well formed, self-contained and animated.
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "client/report/mechanism_drawing.h"
#include "spec/io/drawing_convert.h"
#include "spec/io/study_io.h"
#include "tests/report/markup_checker.h"
#include "worker/engine/scene_drawing.h"

namespace mbopt::report {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

struct Example {
  const char* path;
  size_t instants;
};

class ExampleDrawing : public ::testing::TestWithParam<Example> {};

TEST_P(ExampleDrawing, RendersAsAWellFormedAnimatedPage) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile(GetParam().path);
  ASSERT_TRUE(scene.ok()) << scene.status();
  absl::StatusOr<spec::SceneDrawing> drawn = engine::DrawScene(*scene, scene->DefaultParameterValues());
  ASSERT_TRUE(drawn.ok()) << drawn.status();
  ASSERT_EQ(drawn->failure, "");
  absl::StatusOr<spec::SceneDrawing> read = spec::io::DrawingFromProto(spec::io::DrawingToProto(*drawn));
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->times_s.size(), GetParam().instants);
  ASSERT_EQ(read->points_m.size(), drawn->points_m.size());
  EXPECT_EQ(read->points_m.back().back().x_m, drawn->points_m.back().back().x_m);  // doubles kept bit for bit

  const std::string html = SceneDrawingPageHtml(*read, GetParam().path);
  EXPECT_EQ(testing::CheckMarkup(html, false), "");
  const std::vector<std::string> svgs = testing::SvgFragments(html);
  ASSERT_EQ(svgs.size(), 1u);
  EXPECT_EQ(testing::CheckMarkup(svgs[0], true), "");
  EXPECT_THAT(html, Not(HasSubstr("http")));
  // A slider and its script where there is motion; a schematic is one picture.
  EXPECT_EQ(testing::CountOccurrences(html, "<input type=\"range\""), GetParam().instants > 1 ? 1 : 0);
  EXPECT_EQ(testing::CountOccurrences(html, "<script>"), GetParam().instants > 1 ? 1 : 0);
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"frame\""),
            static_cast<int>(std::min<size_t>(GetParam().instants, kMaxDrawingFrames)));
  EXPECT_GE(testing::CountOccurrences(html, "<g class=\"body\""), 1);
}

INSTANTIATE_TEST_SUITE_P(Examples, ExampleDrawing,
                         ::testing::Values(Example{"examples/press/press.scene.textproto", 101},
                                           Example{"examples/isolator/isolator.scene.textproto", 601},
                                           Example{"examples/fourbar/fourbar_rigid.scene.textproto", 101},
                                           Example{"examples/vehicle/vehicle.scene.textproto", 1}));

TEST(SceneDrawingFile, RefusesAPointIndexPastTheTable) {
  spec::SceneDrawing d;
  d.scene_name = "broken";
  d.AddPoint("only");
  d.times_s = {0.0};
  d.points_m = {{{0.0, 0.0}}};
  d.elements.push_back({"spring", 0, 3, true, false});
  absl::StatusOr<spec::SceneDrawing> read = spec::io::DrawingFromProto(spec::io::DrawingToProto(d));
  ASSERT_FALSE(read.ok());
  EXPECT_THAT(read.status().message(), HasSubstr("elements[0].b is point 3, expected 0 to 0"));
}

TEST(SceneDrawingFile, ExternalScenesHaveNoDrawing) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile("examples/external/quarter_car.scene.textproto");
  ASSERT_TRUE(scene.ok()) << scene.status();
  absl::StatusOr<spec::SceneDrawing> drawn = engine::DrawScene(*scene, scene->DefaultParameterValues());
  ASSERT_FALSE(drawn.ok());
  EXPECT_THAT(drawn.status().message(), HasSubstr("only multibody, linkage and lumped scenes can be drawn"));
}

}  // namespace
}  // namespace mbopt::report
