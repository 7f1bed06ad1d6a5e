// The report page of a Pareto front (client/report/pareto_report.h): well
// formed, one plot of the objective against the traded value with every
// point labelled, dominated and infeasible points set apart, unrun points
// left out of the plot, and the chosen point marked and listed.
#include "client/report/pareto_report.h"

#include <cmath>

#include <gtest/gtest.h>

#include "tests/report/markup_checker.h"

namespace mbopt::report {
namespace {

// Five points: 1, 2, 4 and 5 on the front, 3 dominated; or, with
// `unrun_middle`, 2 to 4 not run.
ParetoReportData Front(bool unrun_middle = false) {
  ParetoReportData data;
  data.job_id = "job-3";
  data.study_name = "a <front>";
  data.state = "completed";
  data.objective_unit = "m/s^2";
  data.against = "s1";
  data.against_unit = "in";
  data.points_total = 5;
  data.variable_names = {"k", "c"};
  data.variable_units = {"N/m", "N s/m"};
  data.constraint_names = {"s1", "s2"};
  const double objective[] = {1.0, 1.2, 1.6, 1.7, 2.5};
  const double value[] = {0.8, 0.6, 0.61, 0.3, 0.1};
  for (int i = 0; i < 5; ++i) {
    ParetoReportData::Point p;
    p.index = i + 1;
    p.level = i == 0 || i == 4 ? std::nan("") : 0.8 - 0.175 * i;
    p.objective = objective[i];
    p.value = value[i];
    p.max_violation = -0.1;
    p.run_state = "converged";
    p.cycles = 7;
    p.status = i == 2 ? "dominated" : "front";
    p.design = {100.0 * (i + 1), 20.0};
    p.constraints = {0.2 - 0.1 * i, -0.5};
    if (unrun_middle && i > 0 && i < 4) {
      p.objective = p.value = p.max_violation = std::nan("");
      p.run_state = "not_run";
      p.status = "not run";
      p.reason = "the objectives do not conflict";
    }
    data.points.push_back(p);
  }
  return data;
}

TEST(ParetoReport, IsWellFormedWithTheFrontLabelledAndTheDominatedPointApart) {
  const std::string html = RenderParetoReportHtml(Front());
  EXPECT_EQ(testing::CheckMarkup(html, /*xml_strict=*/false), "");
  const std::vector<std::string> svgs = testing::SvgFragments(html);
  ASSERT_EQ(svgs.size(), 1u);
  const std::string& svg = svgs[0];
  EXPECT_EQ(testing::CheckMarkup(svg, /*xml_strict=*/true), "");
  EXPECT_NE(svg.find("Pareto front: objective F against the largest value of s1"), std::string::npos);
  EXPECT_NE(svg.find("s1 [in]"), std::string::npos);
  EXPECT_NE(svg.find("F [m/s^2]"), std::string::npos);
  EXPECT_NE(svg.find("on the front"), std::string::npos);
  EXPECT_NE(svg.find("dominated"), std::string::npos);
  for (int k = 1; k <= 5; ++k) {
    EXPECT_NE(svg.find("class=\"point-label\">" + std::to_string(k) + "</text>"), std::string::npos) << k;
  }
  EXPECT_EQ(svg.find("chosen"), std::string::npos);
  EXPECT_NE(html.find("a &lt;front&gt;"), std::string::npos);
  EXPECT_EQ(html.find("Chosen design"), std::string::npos);
}

TEST(ParetoReport, NamesASecondObjectiveAsSuchNotAsAConstraintsLargestValue) {
  ParetoReportData data = Front();
  data.against = "F2: max |s1|";
  data.against_objective = true;
  const std::string html = RenderParetoReportHtml(data);
  EXPECT_EQ(testing::CheckMarkup(html, /*xml_strict=*/false), "");
  const std::vector<std::string> svgs = testing::SvgFragments(html);
  ASSERT_EQ(svgs.size(), 1u);
  EXPECT_NE(svgs[0].find("Pareto front: objective F against the second objective F2: max |s1|"), std::string::npos);
  EXPECT_NE(svgs[0].find("F2: max |s1| [in]"), std::string::npos);
  EXPECT_NE(html.find("<th>traded against</th><td>the second objective F2: max |s1|</td>"), std::string::npos);
  EXPECT_EQ(html.find("the largest value of F2"), std::string::npos);
}

// A maximized second objective is held above each point's level, and the
// front's far end is its greatest value, not its least.
TEST(ParetoReport, SaysAMaximizedSecondObjectiveIsHeldAboveItsLevel) {
  ParetoReportData data = Front();
  data.against = "F2: grip (maximized)";
  data.against_objective = true;
  data.against_maximized = true;
  const std::string html = RenderParetoReportHtml(data);
  EXPECT_EQ(testing::CheckMarkup(html, /*xml_strict=*/false), "");
  EXPECT_NE(html.find("the least F with F2: grip (maximized) held above the point's level"), std::string::npos)
      << html;
  EXPECT_NE(html.find("at the other end: its greatest value"), std::string::npos) << html;
  EXPECT_EQ(html.find("held below"), std::string::npos) << html;
  const std::string minimized = RenderParetoReportHtml(Front());
  EXPECT_NE(minimized.find("held below the point's level"), std::string::npos);
  EXPECT_NE(minimized.find("at the other end: its least value"), std::string::npos);
}

// A maximized F is each point's greatest, not its least.
TEST(ParetoReport, SaysEachPointHasTheGreatestOfAMaximizedObjective) {
  ParetoReportData data = Front();
  data.objective_maximized = true;
  const std::string html = RenderParetoReportHtml(data);
  EXPECT_NE(html.find("Each point is one optimization: the greatest F with"), std::string::npos) << html;
  EXPECT_EQ(html.find("the least F"), std::string::npos) << html;
  EXPECT_NE(RenderParetoReportHtml(Front()).find("Each point is one optimization: the least F with"),
            std::string::npos);
}

// The chosen point's run's history is drawn as a single job's: the history
// plots and the table of LP solves; without records, the note says why.
TEST(ParetoReport, DrawsTheChosenPointsRunHistoryOrSaysWhyNot) {
  ParetoReportData data = Front();
  data.chosen = 2;
  for (int cycle = 1; cycle <= 3; ++cycle) {
    ReportCycle c;
    c.cycle = cycle;
    c.accepted = true;
    c.x0_scaled = c.x_trial_scaled = {1.0 + 0.1 * cycle, 2.0};
    c.objective_x0 = 2.0 - 0.1 * (cycle - 1);
    c.objective_trial = 2.0 - 0.1 * cycle;
    c.max_violation_x0 = c.max_violation_trial = -0.01;
    c.max_approximation_error = 0.05;
    c.move_limits = c.move_limits_next = {0.2, 0.2};
    c.analyses_total = 3 * cycle;
    data.chosen_history.records.push_back(c);
  }
  data.chosen_history.variables.resize(2);
  const std::string html = RenderParetoReportHtml(data);
  EXPECT_EQ(testing::CheckMarkup(html, /*xml_strict=*/false), "");
  const size_t history = html.find("<h2>Cycle history of point 2's run</h2>");
  ASSERT_NE(history, std::string::npos) << html;
  EXPECT_LT(history, html.find("<h2>Responses of point 2</h2>"));
  // The front, then the run's objective, violation, error, move limits and
  // design variables.
  EXPECT_EQ(testing::SvgFragments(html).size(), 6u);
  EXPECT_NE(html.find("<table class=\"cycles\"", history), std::string::npos);

  data.chosen_history = ReportData{};
  data.chosen_history_note = "The cycles are not in the log.";
  const std::string without = RenderParetoReportHtml(data);
  EXPECT_NE(without.find("<h2>Cycle history of point 2's run</h2>\n<p class=\"note\">The cycles are not in the "
                         "log.</p>"),
            std::string::npos)
      << without;
  EXPECT_EQ(testing::SvgFragments(without).size(), 1u);
}

// A point added by refinement (number 6) lies between points 2 and 4 on the
// front: the front's line goes through it there, not after point 5.
TEST(ParetoReport, JoinsTheFrontInTheOrderOfTheTradedValueNotOfThePoints) {
  ParetoReportData data = Front();
  ParetoReportData::Point added = data.points[1];
  added.index = 6;
  added.level = 0.45;
  added.value = 0.45;
  added.objective = 1.4;
  data.points.push_back(added);
  data.points_total = 6;
  const std::vector<std::string> svgs = testing::SvgFragments(RenderParetoReportHtml(data));
  ASSERT_EQ(svgs.size(), 1u);
  auto label = [&](int k) { return svgs[0].find("class=\"point-label\">" + std::to_string(k) + "</text>"); };
  ASSERT_NE(label(6), std::string::npos);
  EXPECT_LT(label(2), label(6));
  EXPECT_LT(label(6), label(4));
  EXPECT_LT(label(4), label(5));
}

TEST(ParetoReport, MarksAndListsTheChosenPoint) {
  ParetoReportData data = Front();
  data.chosen = 4;
  const std::string html = RenderParetoReportHtml(data);
  EXPECT_EQ(testing::CheckMarkup(html, /*xml_strict=*/false), "");
  EXPECT_NE(html.find("chosen: point 4"), std::string::npos);
  EXPECT_NE(html.find("<tr class=\"chosen\"><td class=\"num\">4</td>"), std::string::npos);
  EXPECT_NE(html.find("<h2>Chosen design: point 4</h2>"), std::string::npos);
  // Its design, and its constraints against the study's limits (s1 at -0.1
  // is met: no red cell).
  EXPECT_NE(html.find("<tr><th>k [N/m]</th><td class=\"num\">400</td></tr>"), std::string::npos);
  EXPECT_NE(html.find("<tr><th>s1</th><td class=\"num\">-0.1</td></tr>"), std::string::npos);
}

// The chosen point's responses over time against the initial design's, as
// a single job's page draws them, the point named where "final design"
// would be; a scalar response as bars.
TEST(ParetoReport, DrawsTheChosenPointsResponsesAgainstTheInitialDesign) {
  ParetoReportData data = Front();
  data.chosen = 4;
  ResponsePlot travel;
  travel.title = "s1: max_abs <= 0.5 in";
  travel.unit = "in";
  travel.times_s = {0.0, 0.5, 1.0};
  travel.initial = {0.0, 0.7, 0.2};
  travel.final = {0.0, 0.3, 0.1};
  travel.final_label = "point 4";
  travel.limits.push_back({0.5, "limit"});
  ResponsePlot mass;
  mass.title = "mass";
  mass.unit = "kg";
  mass.times_s = {0.0};
  mass.initial = {2.0};
  mass.final = {1.5};
  mass.final_label = "point 4";
  data.chosen_responses = {travel, mass};
  const std::string html = RenderParetoReportHtml(data);
  EXPECT_EQ(testing::CheckMarkup(html, /*xml_strict=*/false), "");
  EXPECT_NE(html.find("<h2>Responses of point 4</h2>"), std::string::npos);
  const std::vector<std::string> svgs = testing::SvgFragments(html);
  ASSERT_EQ(svgs.size(), 3u);  // the front, the travel over time, the mass as bars
  EXPECT_NE(svgs[1].find("s1: max_abs &lt;= 0.5 in"), std::string::npos);
  EXPECT_NE(svgs[1].find("point 4"), std::string::npos);
  EXPECT_NE(svgs[1].find("initial design"), std::string::npos);
  EXPECT_EQ(svgs[1].find("final design"), std::string::npos);
  EXPECT_NE(svgs[2].find("point 4"), std::string::npos);
  for (const std::string& svg : svgs) EXPECT_EQ(testing::CheckMarkup(svg, /*xml_strict=*/true), "");
}

TEST(ParetoReport, SaysWhyTheChosenPointHasNoResponses) {
  ParetoReportData data = Front();
  data.chosen = 2;
  data.chosen_responses_note = "The responses are not shown: point 2 has no design of its own.";
  const std::string html = RenderParetoReportHtml(data);
  EXPECT_NE(html.find("<h2>Responses of point 2</h2>"), std::string::npos);
  EXPECT_NE(html.find("point 2 has no design of its own."), std::string::npos);
  EXPECT_EQ(RenderParetoReportHtml(Front()).find("Responses of point"), std::string::npos);
}

TEST(ParetoReport, UnrunPointsAreListedWithTheirReasonAndNotDrawn) {
  const std::string html = RenderParetoReportHtml(Front(/*unrun_middle=*/true));
  EXPECT_EQ(testing::CheckMarkup(html, /*xml_strict=*/false), "");
  const std::vector<std::string> svgs = testing::SvgFragments(html);
  ASSERT_EQ(svgs.size(), 1u);
  EXPECT_NE(svgs[0].find(">1</text>"), std::string::npos);
  EXPECT_EQ(svgs[0].find("class=\"point-label\">3</text>"), std::string::npos);
  EXPECT_NE(html.find("not run: the objectives do not conflict"), std::string::npos);
  for (const char* nan : {"\"nan", "nan\"", ">nan", " nan", ",nan"}) {
    EXPECT_EQ(html.find(nan), std::string::npos) << nan;
  }
}

// A front of three objectives: the same five points with a third value
// (s2, in inches), drawn as its three pairwise projections.
TEST(ParetoReport, AFrontOfThreeObjectivesIsDrawnAsItsThreeProjections) {
  ParetoReportData data = Front();
  data.three = true;
  data.against3 = "s2";
  data.against3_unit = "in";
  data.chosen = 4;
  for (size_t k = 0; k < data.points.size(); ++k) {
    data.points[k].value3 = 0.1 * static_cast<double>(k + 1);
    data.points[k].level3 = k < 3 ? std::nan("") : 0.42;
  }
  const std::string html = RenderParetoReportHtml(data);
  EXPECT_EQ(testing::CheckMarkup(html, /*xml_strict=*/false), "");
  const std::vector<std::string> svgs = testing::SvgFragments(html);
  ASSERT_EQ(svgs.size(), 3u);
  EXPECT_NE(svgs[0].find("F against s1"), std::string::npos);
  EXPECT_NE(svgs[1].find("F against s2"), std::string::npos);
  EXPECT_NE(svgs[2].find("s2 against s1"), std::string::npos);
  for (const std::string& svg : svgs) {
    EXPECT_EQ(testing::CheckMarkup(svg, /*xml_strict=*/true), "");
    EXPECT_NE(svg.find("chosen: point 4"), std::string::npos);
    for (int k = 1; k <= 5; ++k) {
      EXPECT_NE(svg.find("class=\"point-label\">" + std::to_string(k) + "</text>"), std::string::npos) << k;
    }
  }
  EXPECT_NE(svgs[2].find("s2 [in]"), std::string::npos);
  EXPECT_NE(html.find("level3 [in]"), std::string::npos);
  EXPECT_NE(html.find("and the largest value of s2"), std::string::npos);
  EXPECT_NE(html.find("0.42"), std::string::npos);
}

}  // namespace
}  // namespace mbopt::report
