// Drawings of a study with load cases (client/report/load_case_drawings.h)
// on synthetic drawings: the report's section and `mbopt draw`'s page have
// one figure per case, headed and labelled with the case's name, with ids
// of their own, well formed.
#include "client/report/load_case_drawings.h"

#include <cmath>
#include <numbers>
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

// A crank of radius `radius_m` pinned to the ground at O, `instants`
// instants over one turn.
spec::SceneDrawing Crank(double radius_m, int instants) {
  spec::SceneDrawing d;
  d.scene_name = "crank";
  const int o = d.AddPoint("O"), a = d.AddPoint("A");
  d.bodies.push_back({"crank", {o, a}});
  d.joints.push_back({"O", spec::SceneDrawing::JointKind::kPin, o, {}});
  d.ground_points.push_back(o);
  for (int i = 0; i < instants; ++i) {
    const double th = 2 * std::numbers::pi * i / instants;
    d.times_s.push_back(static_cast<double>(i) / instants);
    d.points_m.push_back({{0, 0}, {radius_m * std::cos(th), radius_m * std::sin(th)}});
  }
  return d;
}

TEST(LoadCaseDrawings, TheReportDrawsEachCaseHeadedByItsName) {
  ReportData data = testing::SyntheticVehicleReport();
  data.mechanism.cases.push_back(LoadCaseDrawings{"smooth", Crank(1.0, 8), Crank(1.5, 8), ""});
  data.mechanism.cases.push_back(LoadCaseDrawings{"rough <road>", Crank(0.5, 6), Crank(0.75, 6), ""});
  const std::string html = RenderJobReportHtml(data);
  EXPECT_EQ(testing::CountOccurrences(html, "<h2>Mechanism</h2>"), 1);
  EXPECT_THAT(html, HasSubstr("once per load case"));
  EXPECT_THAT(html, HasSubstr("<h3>Load case smooth</h3>"));
  EXPECT_THAT(html, HasSubstr("<h3>Load case rough &lt;road&gt;</h3>"));
  EXPECT_THAT(html, HasSubstr(">initial design, smooth</text>"));
  EXPECT_THAT(html, HasSubstr(">final design, rough &lt;road&gt;</text>"));
  // The cases in the study's order, each its own animated figure.
  EXPECT_LT(html.find("Load case smooth"), html.find("Load case rough"));
  EXPECT_THAT(html, HasSubstr("id=\"mechanism-case-0\""));
  EXPECT_THAT(html, HasSubstr("id=\"mechanism-case-1\""));
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"frame\""), 8 + 6);
  // A slider each, and one above them that moves both.
  EXPECT_EQ(testing::CountOccurrences(html, "<input type=\"range\""), 3);
  EXPECT_LT(html.find("id=\"cases-time\">Every case:"), html.find("<h3>Load case smooth</h3>"));
  EXPECT_THAT(html, HasSubstr("var ids=[\"mechanism-case-0\",\"mechanism-case-1\"]"));
  EXPECT_EQ(testing::CheckMarkup(html, false), "");
  for (const std::string& svg : testing::SvgFragments(html)) EXPECT_EQ(testing::CheckMarkup(svg, true), "");
}

TEST(LoadCaseDrawings, ACaseThatCouldNotBeDrawnSaysWhyUnderItsName) {
  ReportData data = testing::SyntheticVehicleReport();
  data.mechanism.cases.push_back(LoadCaseDrawings{"smooth", Crank(1.0, 4), std::nullopt, ""});
  data.mechanism.cases.push_back(
      LoadCaseDrawings{"locked", std::nullopt, std::nullopt, "The initial design could not be drawn: it locks."});
  data.mechanism.note = "The job has no final design yet: only the initial design is drawn.";
  const std::string html = RenderJobReportHtml(data);
  const size_t locked = html.find("<h3>Load case locked</h3>");
  ASSERT_NE(locked, std::string::npos);
  EXPECT_LT(locked, html.find("The initial design could not be drawn: it locks."));
  EXPECT_THAT(html, HasSubstr("The job has no final design yet"));
  EXPECT_THAT(html, Not(HasSubstr("id=\"mechanism-case-1\"")));
  EXPECT_EQ(testing::CountOccurrences(html, "<g class=\"frame\""), 4);
  // One figure has nothing to share a slider with.
  EXPECT_THAT(html, Not(HasSubstr("cases-time")));
}

TEST(LoadCaseDrawings, TheDrawPageHasAFigurePerCase) {
  const std::string html = LoadCaseDrawingsPageHtml({CaseDrawing{"as_built", Crank(1.0, 5)},
                                                     CaseDrawing{"long_crank", Crank(2.0, 5)}},
                                                    "crank study", "crank.study.textproto");
  EXPECT_EQ(testing::CheckMarkup(html, false), "");
  EXPECT_THAT(html, HasSubstr("<h1>crank study</h1>"));
  EXPECT_THAT(html, HasSubstr("once per load case (2)"));
  EXPECT_THAT(html, HasSubstr("<h2>Load case as_built</h2>"));
  EXPECT_THAT(html, HasSubstr("<h2>Load case long_crank</h2>"));
  EXPECT_THAT(html, HasSubstr(">long_crank</text>"));
  EXPECT_THAT(html, HasSubstr("id=\"drawing-case-0\""));
  EXPECT_THAT(html, HasSubstr("id=\"drawing-case-1\""));
  EXPECT_EQ(testing::SvgFragments(html).size(), 2u);
  EXPECT_THAT(html, Not(HasSubstr("http")));
  // The shared slider steps through the longer grid's instants.
  EXPECT_THAT(html, HasSubstr("Every case: <button type=\"button\">Play</button> <input type=\"range\" min=\"0\" max=\"4\""));
}

// A bar 1 m long sliding 4 m along x over `instants` instants.
spec::SceneDrawing SlidingBar(int instants) {
  spec::SceneDrawing d;
  d.scene_name = "bar";
  const int a = d.AddPoint("A"), b = d.AddPoint("B");
  d.bodies.push_back({"bar", {a, b}});
  for (int i = 0; i < instants; ++i) {
    const double x = 4.0 * i / (instants - 1);
    d.times_s.push_back(static_cast<double>(i) / instants);
    d.points_m.push_back({{x, 0}, {x + 1, 0}});
  }
  return d;
}

// The opening tags of a page's drawings' <svg> elements.
std::vector<std::string> SvgTags(const std::string& html) {
  std::vector<std::string> tags;
  for (size_t p = html.find("<svg class=\"drawing\""); p != std::string::npos;
       p = html.find("<svg class=\"drawing\"", p + 1)) {
    tags.push_back(html.substr(p, html.find('>', p) - p));
  }
  return tags;
}

// Cases on one scale and window: a crank turning in a 2 m square and a bar
// sliding along a 5 m line get figures of the same size, each holding both
// motions (alone, the bar's figure would be a thin strip).
TEST(LoadCaseDrawings, TheCasesShareTheirAxes) {
  const std::string page = LoadCaseDrawingsPageHtml(
      {CaseDrawing{"turning", Crank(1.0, 8)}, CaseDrawing{"sliding", SlidingBar(8)}}, "study", "s.study.textproto");
  const std::vector<std::string> tags = SvgTags(page);
  ASSERT_EQ(tags.size(), 2u);
  EXPECT_EQ(tags[0], tags[1]);
  const std::vector<std::string> alone = SvgTags(LoadCaseDrawingsPageHtml(
      {CaseDrawing{"sliding", SlidingBar(8)}}, "study", "s.study.textproto"));
  ASSERT_EQ(alone.size(), 1u);
  EXPECT_NE(alone[0], tags[1]) << "the bar alone is drawn on axes of its own";

  ReportData data = testing::SyntheticVehicleReport();
  data.mechanism.cases.push_back(LoadCaseDrawings{"turning", Crank(1.0, 8), Crank(1.0, 8), ""});
  data.mechanism.cases.push_back(LoadCaseDrawings{"sliding", SlidingBar(8), SlidingBar(8), ""});
  const std::vector<std::string> report = SvgTags(RenderJobReportHtml(data));
  ASSERT_EQ(report.size(), 2u);
  EXPECT_EQ(report[0], report[1]);
}

}  // namespace
}  // namespace mbopt::report
