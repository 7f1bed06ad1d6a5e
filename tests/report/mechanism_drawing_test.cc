// The animated drawing of a scene (client/report/mechanism_drawing.h) on
// synthetic drawings: well formed, self-contained, one frame per instant,
// equal axis scaling, the slider and its script, the report's section.
#include "client/report/mechanism_drawing.h"

#include <cmath>
#include <regex>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "client/report/job_report_html.h"
#include "tests/report/markup_checker.h"
#include "tests/report/synthetic_report.h"

namespace mbopt::report {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// A crank (ground pin O, end A on a circle of 1 m) and a block on a slider
// along x, joined by a spring with a damper; `instants` instants over one
// turn.
spec::SceneDrawing CrankAndSlider(int instants) {
  spec::SceneDrawing d;
  d.scene_name = "crank <&> slider";
  const int o = d.AddPoint("O"), a = d.AddPoint("A"), s = d.AddPoint("S");
  d.bodies.push_back({"crank", {o, a}});
  d.bodies.push_back({"block", {s}});
  d.joints.push_back({"O", spec::SceneDrawing::JointKind::kPin, o, {}});
  d.joints.push_back({"guide", spec::SceneDrawing::JointKind::kSlider, s, {}});
  d.elements.push_back({"spring", a, s, true, true});
  d.ground_points.push_back(o);
  for (int i = 0; i < instants; ++i) {
    const double t = static_cast<double>(i) / instants;
    d.times_s.push_back(t);
    const double th = 2 * M_PI * t;
    d.points_m.push_back({{0, 0}, {std::cos(th), std::sin(th)}, {3, 0}});
    d.joints[1].axis_angle_rad.push_back(0.0);
  }
  return d;
}

TEST(MechanismDrawing, PageIsWellFormedAndSelfContained) {
  const std::string html = SceneDrawingPageHtml(CrankAndSlider(12), "crank.scene.textproto");
  EXPECT_EQ(testing::CheckMarkup(html, false), "");
  const std::vector<std::string> svgs = testing::SvgFragments(html);
  ASSERT_EQ(svgs.size(), 1u);
  EXPECT_EQ(testing::CheckMarkup(svgs[0], true), "");
  EXPECT_THAT(html, Not(HasSubstr("http:")));
  EXPECT_THAT(html, Not(HasSubstr("https:")));
  EXPECT_THAT(html, Not(HasSubstr("src=")));
  EXPECT_THAT(html, Not(HasSubstr("href=")));
  EXPECT_THAT(html, Not(HasSubstr("url(")));
  EXPECT_THAT(html, HasSubstr("<h1>crank &lt;&amp;&gt; slider</h1>"));
}

TEST(MechanismDrawing, OneFrameShownPerInstantWithSliderAndPlayButton) {
  const std::string html = SceneDrawingPageHtml(CrankAndSlider(12), "crank.scene.textproto");
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"frame\""), 12);
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"frame\" display=\"none\""), 11);
  EXPECT_THAT(html, HasSubstr("<input type=\"range\" min=\"0\" max=\"11\" value=\"0\""));
  EXPECT_THAT(html, HasSubstr("<button type=\"button\">Play</button>"));
  EXPECT_THAT(html, HasSubstr("<span class=\"time\">t = 0 s</span>"));
  EXPECT_EQ(testing::CountOccurrences(html, "<script>"), 1);
  // Each kind of part has its symbol in every frame.
  EXPECT_EQ(testing::CountOccurrences(html, "<circle class=\"pin\""), 12);
  EXPECT_EQ(testing::CountOccurrences(html, "<polygon class=\"slider\""), 12);
  EXPECT_EQ(testing::CountOccurrences(html, "<polyline class=\"axis\""), 12);
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"ground\""), 1);  // drawn once: it does not move
}

TEST(MechanismDrawing, OneInstantIsOnePictureWithoutControls) {
  const std::string html = SceneDrawingPageHtml(CrankAndSlider(1), "crank.scene.textproto");
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"frame\""), 1);
  EXPECT_THAT(html, Not(HasSubstr("<input")));
  EXPECT_THAT(html, Not(HasSubstr("<script")));
  EXPECT_THAT(html, HasSubstr("<span class=\"time\">t = 0 s</span>"));
  EXPECT_EQ(testing::CheckMarkup(html, false), "");
}

// A rotational spring-damper at a pin, a force and a torque: each has its
// symbol (named in its tooltip) in every frame, and the page stays well formed.
TEST(MechanismDrawing, RotationalSpringsForcesAndTorquesHaveTheirSymbols) {
  spec::SceneDrawing d = CrankAndSlider(5);
  d.joints[0].rotational_spring = true;
  d.joints[0].rotational_damper = true;
  d.loads.push_back({"force at block", spec::SceneDrawing::LoadKind::kForce, 2, -1.0, 0.0});
  d.loads.push_back({"torque on crank", spec::SceneDrawing::LoadKind::kTorque, 1, -1.0, 0.0});
  const std::string html = SceneDrawingPageHtml(d, "crank.scene.textproto");
  EXPECT_EQ(testing::CheckMarkup(html, false), "");
  for (const std::string& svg : testing::SvgFragments(html)) EXPECT_EQ(testing::CheckMarkup(svg, true), "");
  EXPECT_EQ(testing::CountOccurrences(html, "<polyline class=\"rotational-spring\""), 5);
  EXPECT_EQ(testing::CountOccurrences(html, "<path class=\"rotational-damper\""), 5);
  EXPECT_EQ(testing::CountOccurrences(html, "<title>O: rotational spring and damper</title>"), 5);
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"load\"><title>force at block</title>"), 5);
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"load\"><title>torque on crank</title>"), 5);
  // Without them, none of these symbols.
  const std::string plain = SceneDrawingPageHtml(CrankAndSlider(5), "crank.scene.textproto");
  EXPECT_THAT(plain, Not(HasSubstr("rotational")));
  EXPECT_THAT(plain, Not(HasSubstr("class=\"load\"")));
}

TEST(MechanismDrawing, LongGridsAreThinnedToTheFrameLimit) {
  const std::string html = SceneDrawingPageHtml(CrankAndSlider(1000), "crank.scene.textproto");
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"frame\""), kMaxDrawingFrames);
  EXPECT_THAT(html, HasSubstr("(240 of 1000 instants shown)"));
}

// x and y share one scale: the crank's end 1 m from O is as far from it on
// screen at 0 and at 90 degrees.
TEST(MechanismDrawing, AxesShareOneScale) {
  const std::string html = SceneDrawingPageHtml(CrankAndSlider(4), "crank.scene.textproto");
  // The points' small dots, in point order, frame after frame.
  const std::regex dot("<circle cx=\"([-0-9.]+)\" cy=\"([-0-9.]+)\" r=\"1.6\"");
  std::vector<std::pair<double, double>> dots;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), dot); it != std::sregex_iterator(); ++it) {
    dots.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]));
  }
  ASSERT_EQ(dots.size(), 12u);  // 3 points x 4 frames
  const auto o = dots[0], a0 = dots[1], a90 = dots[4];
  const double along_x = std::hypot(a0.first - o.first, a0.second - o.second);
  const double along_y = std::hypot(a90.first - o.first, a90.second - o.second);
  EXPECT_GT(along_x, 50.0);  // a visible size
  EXPECT_NEAR(along_x, along_y, 0.2);  // coordinates are written to 0.1 px
  EXPECT_LT(a90.second, o.second);  // +y is up on screen
}

TEST(MechanismDrawing, TheReportShowsBothDesignsWhenDrawn) {
  ReportData data = testing::SyntheticVehicleReport();
  data.mechanism.initial = CrankAndSlider(8);
  data.mechanism.final = CrankAndSlider(8);
  const std::string html = RenderJobReportHtml(data);
  EXPECT_THAT(html, HasSubstr("<h2>Mechanism</h2>"));
  EXPECT_THAT(html, HasSubstr(">initial design</text>"));
  EXPECT_THAT(html, HasSubstr(">final design</text>"));
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"frame\""), 8);
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"layer\""), 16);
  EXPECT_EQ(testing::CheckMarkup(html, false), "");
  for (const std::string& svg : testing::SvgFragments(html)) EXPECT_EQ(testing::CheckMarkup(svg, true), "");
  const size_t from = html.find("<h2>Mechanism</h2>"), to = html.find("<h2>Cycle history</h2>");
  ASSERT_LT(from, to);  // the model first
  EXPECT_THAT(html.substr(from, to - from), Not(HasSubstr("http")));
}

TEST(MechanismDrawing, TheReportSaysWhyThereIsNoDrawing) {
  ReportData data = testing::SyntheticVehicleReport();
  data.mechanism.note = "Not drawn (mbopt report --no-mechanism).";
  const std::string html = RenderJobReportHtml(data);
  EXPECT_THAT(html, HasSubstr("<h2>Mechanism</h2>"));
  EXPECT_THAT(html, HasSubstr("Not drawn (mbopt report --no-mechanism)."));
  EXPECT_THAT(html, Not(HasSubstr("<script")));
}

TEST(MechanismDrawing, AStoppedMotionIsSaid) {
  spec::SceneDrawing d = CrankAndSlider(3);
  d.failure = "the mechanism locks at joint 'A'";
  const std::string html = SceneDrawingPageHtml(d, "crank.scene.textproto");
  EXPECT_THAT(html, HasSubstr("the motion stops at t = 0.666667 s: the mechanism locks at joint &#39;A&#39;"));
}

TEST(MechanismDrawing, TheDrawingsNoteIsSaid) {
  spec::SceneDrawing d = CrankAndSlider(3);
  d.note = "the flexible links are drawn rigid <as the analysis moves them>";
  const std::string html = SceneDrawingPageHtml(d, "crank.scene.textproto");
  EXPECT_THAT(html, HasSubstr("The drawing: the flexible links are drawn rigid &lt;as the analysis moves them&gt;."));
}

}  // namespace
}  // namespace mbopt::report
