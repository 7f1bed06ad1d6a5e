#include "client/report/job_report_html.h"

#include <cmath>
#include <limits>
#include <random>
#include <regex>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "client/report/history_plots.h"
#include "client/report/report_tables.h"
#include "client/report/response_plots.h"
#include "tests/report/markup_checker.h"
#include "tests/report/synthetic_report.h"

namespace mbopt::report {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

int Count(const std::string& haystack, const std::string& needle) {
  return testing::CountOccurrences(haystack, needle);
}

// The table row of a design variable, from its name cell to the row end.
std::string DesignRow(const std::string& html, const std::string& name) {
  const std::size_t table = html.find("<table class=\"design\">");
  const std::size_t start = html.find("<tr><td>" + name + "</td>", table);
  if (table == std::string::npos || start == std::string::npos) return "";
  return html.substr(start, html.find("</tr>", start) - start);
}

void ExpectWellFormedWithCleanCoordinates(const std::string& html) {
  EXPECT_EQ(testing::CheckMarkup(html, /*xml_strict=*/false), "");
  static const std::regex kNumbers("^[-0-9., ]*$");
  for (const std::string& svg : testing::SvgFragments(html)) {
    EXPECT_EQ(testing::CheckMarkup(svg, /*xml_strict=*/true), "");
    for (const std::string& v : testing::NumericAttributeValues(svg)) {
      EXPECT_TRUE(std::regex_match(v, kNumbers)) << "attribute value '" << v << "'";
    }
  }
}

TEST(JobReportHtml, IsWellFormedAndSelfContained) {
  const std::string html = RenderJobReportHtml(testing::SyntheticVehicleReport());
  ExpectWellFormedWithCleanCoordinates(html);
  EXPECT_EQ(testing::SvgFragments(html).size(), 5u);
  EXPECT_THAT(html, Not(HasSubstr("<script")));
  EXPECT_THAT(html, Not(HasSubstr("http://www.w3.org/1999")));  // no other namespaces than SVG's
  EXPECT_THAT(html, Not(HasSubstr("src=")));
  EXPECT_THAT(html, Not(HasSubstr("href=")));
  EXPECT_THAT(html, Not(HasSubstr("url(")));
  EXPECT_THAT(html, Not(HasSubstr("@import")));
}

TEST(JobReportHtml, EscapesTheStudyName) {
  const std::string html = RenderJobReportHtml(testing::SyntheticVehicleReport());
  EXPECT_THAT(html, HasSubstr("<h1>vehicle &lt;suspension&gt; &amp; &quot;seat&quot;</h1>"));
  EXPECT_THAT(html, Not(HasSubstr(testing::kSyntheticStudyName)));
}

TEST(JobReportHtml, EscapesVariableAndConstraintNamesEverywhere) {
  ReportData data = testing::SyntheticVehicleReport();
  data.variables[0].name = "k<1>&\"x\"";
  for (ReportCycle& r : data.records) {
    if (!r.worst_constraint.empty()) r.worst_constraint = "g<&>";
  }
  const std::string html = RenderJobReportHtml(data);
  ExpectWellFormedWithCleanCoordinates(html);
  EXPECT_THAT(html, Not(HasSubstr("k<1>")));
  EXPECT_THAT(html, Not(HasSubstr("g<&>")));
  EXPECT_GE(Count(html, "k&lt;1&gt;&amp;&quot;x&quot;"), 3);  // two legends and the design table
  EXPECT_THAT(html, HasSubstr("g&lt;&amp;&gt;"));
}

TEST(JobReportHtml, ShowsTheSummary) {
  const std::string html = RenderJobReportHtml(testing::SyntheticVehicleReport());
  EXPECT_THAT(html, HasSubstr("<strong>converged</strong>"));
  EXPECT_THAT(html, HasSubstr("<th>cycles</th><td>11</td>"));
  EXPECT_THAT(html, HasSubstr("<th>final objective F</th><td>252 in/s^2</td>"));
  EXPECT_THAT(html, HasSubstr("<th>max violation maxg</th><td>0.00025 (within the tolerance 0.005)</td>"));
}

TEST(JobReportHtml, FailedAnalysesLeaveNoNanInThePlots) {
  const std::string html = RenderJobReportHtml(testing::SyntheticVehicleReport());
  for (const std::string& svg : testing::SvgFragments(html)) {
    EXPECT_THAT(svg, Not(HasSubstr("nan")));
    EXPECT_THAT(svg, Not(HasSubstr("inf\"")));
  }
  EXPECT_THAT(html, HasSubstr("analysis failed"));  // the table says what happened
}

TEST(JobReportHtml, MarksRejectedTrialPoints) {
  const std::string html = RenderJobReportHtml(testing::SyntheticVehicleReport());
  const std::string objective_plot = testing::SvgFragments(html)[0];
  // Cycle 2's rejected trial has F(x*) = 380; cycle 5's failed and has no point.
  EXPECT_EQ(Count(objective_plot, "fill=\"white\" stroke=\"#d62728\""), 1 + 1);  // point and legend
  EXPECT_THAT(objective_plot, HasSubstr("rejected trial F(x*)"));
  EXPECT_EQ(Count(html, "<tr class=\"rejected\">"), 2);
  EXPECT_THAT(html, HasSubstr("rejected: maxfout 0.62 &gt; 0.40"));
}

TEST(JobReportHtml, DrawsTheErrorThresholds) {
  const std::string html = RenderJobReportHtml(testing::SyntheticVehicleReport());
  const std::string errors = testing::SvgFragments(html)[2];
  EXPECT_THAT(errors, HasSubstr("0.10 widen below"));
  EXPECT_THAT(errors, HasSubstr("0.25 narrow above"));
  EXPECT_THAT(errors, HasSubstr("0.40 reject above"));
  EXPECT_EQ(Count(errors, "stroke-dasharray=\"6 4\""), 3);
}

TEST(JobReportHtml, ErrorsSpanningDecadesGetALogAxisWithZerosOnTheFloor) {
  const ReportData data = testing::SyntheticVehicleReport();
  const PlotSpec errors = ApproximationErrorPlot(data);
  EXPECT_TRUE(errors.log_y);  // e_o falls from 0.3 to 0.0025
  const std::string svg = RenderLinePlotSvg(errors);
  EXPECT_THAT(svg, HasSubstr("<polygon"));  // e_o = 0 in cycle 6
}

TEST(JobReportHtml, ObjectiveGetsALogAxisOnlyWhenPositiveAndSpanningDecades) {
  ReportData data = testing::SyntheticVehicleReport();
  EXPECT_FALSE(ObjectivePlot(data).log_y);  // 252 ... 380
  for (ReportCycle& r : data.records) r.objective_trial /= 1000.0 * r.cycle;
  EXPECT_TRUE(ObjectivePlot(data).log_y);   // 333 down to ~0.02
  data.records.back().objective_trial = -1.0;
  EXPECT_FALSE(ObjectivePlot(data).log_y);
}

TEST(JobReportHtml, LinearScaleCanBeForced) {
  ReportData data = testing::SyntheticVehicleReport();
  data.error_scale = ScaleChoice::kLinear;
  EXPECT_FALSE(ApproximationErrorPlot(data).log_y);
  data.violation_scale = ScaleChoice::kLog;
  EXPECT_TRUE(ViolationPlot(data).log_y);
}

TEST(JobReportHtml, PlotsOneLinePerDesignVariableWithItsName) {
  const ReportData data = testing::SyntheticVehicleReport();
  const PlotSpec design = DesignVariablePlot(data);
  ASSERT_EQ(design.series.size(), 6u);
  EXPECT_EQ(design.series[3].name, "c1");
  EXPECT_EQ(design.series[3].x.size(), 12u);  // initial design and 11 cycles
  const PlotSpec limits = MoveLimitPlot(data);
  int in_legend = 0;
  for (const PlotSeries& s : limits.series) in_legend += s.in_legend ? 1 : 0;
  EXPECT_EQ(in_legend, 6 + 1);  // six variables and the key for rejected attempts
}

TEST(JobReportHtml, FlagsVariablesOnTheirBounds) {
  const std::string html = RenderJobReportHtml(testing::SyntheticVehicleReport());
  EXPECT_THAT(DesignRow(html, "k1"), HasSubstr("at lower bound"));
  EXPECT_THAT(DesignRow(html, "k2"), HasSubstr("at lower bound"));
  EXPECT_THAT(DesignRow(html, "k3"), HasSubstr("at lower bound"));
  EXPECT_THAT(DesignRow(html, "c1"), Not(HasSubstr("bound</td>")));
  EXPECT_THAT(DesignRow(html, "c2"), Not(HasSubstr("bound</td>")));
  EXPECT_THAT(DesignRow(html, "c3"), HasSubstr("at upper bound"));
  // Physical units: k1 = 10 x1 with x1 = 5 on its lower bound.
  EXPECT_THAT(DesignRow(html, "k1"), HasSubstr("<td class=\"num\">50</td><td>lb/in</td><td class=\"num\">50</td>"));
}

TEST(DesignBoundFlag, UsesTheScaledRangeAsTolerance) {
  const ReportVariable v{"a", "m", 2.0, true, 1.0, 3.0};
  EXPECT_EQ(DesignBoundFlag(v, 2.0), BoundFlag::kAtLower);
  EXPECT_EQ(DesignBoundFlag(v, 2.0 * (1 + 1e-9)), BoundFlag::kAtLower);
  EXPECT_EQ(DesignBoundFlag(v, 2.01), BoundFlag::kNone);
  EXPECT_EQ(DesignBoundFlag(v, 6.0), BoundFlag::kAtUpper);
  EXPECT_EQ(DesignBoundFlag(v, std::nan("")), BoundFlag::kUnknown);
  const ReportVariable negative_scale{"b", "", -1.0, true, 1.0, 3.0};
  EXPECT_EQ(DesignBoundFlag(negative_scale, -3.0), BoundFlag::kAtUpper);
  const ReportVariable no_bounds{"c", "", 1.0, false, 0, 0};
  EXPECT_EQ(DesignBoundFlag(no_bounds, 0.0), BoundFlag::kUnknown);
}

TEST(JobReportHtml, NamesTheActiveConstraintHonestly) {
  const std::string html = RenderJobReportHtml(testing::SyntheticVehicleReport());
  EXPECT_THAT(html, HasSubstr("<td>seat-chassis@t=0.42s upper</td>"));
  EXPECT_THAT(html, HasSubstr("keeps only the most critical row"));
}

TEST(JobReportHtml, SaysWhenTheWorstRowIsNotActive) {
  ReportData data = testing::SyntheticVehicleReport();
  data.records.back().max_violation_trial = -0.2;
  const std::string html = RenderJobReportHtml(data);
  EXPECT_THAT(html, Not(HasSubstr("<table class=\"active\">")));
  EXPECT_THAT(html, HasSubstr("No row is known to be active"));
}

TEST(JobReportHtml, ListsExtraActiveRowsWhenGiven) {
  ReportData data = testing::SyntheticVehicleReport();
  data.active_constraints.push_back({"rear wheel-road@t=0.10s lower", -0.001});
  data.active_constraints.push_back({"front wheel-road@t=0.10s lower", -0.4});  // not active
  const std::string html = RenderJobReportHtml(data);
  EXPECT_THAT(html, HasSubstr("rear wheel-road@t=0.10s lower"));
  EXPECT_THAT(html, Not(HasSubstr("front wheel-road")));
  EXPECT_THAT(html, Not(HasSubstr("keeps only the most critical row")));
}

TEST(JobReportHtml, AJobWithoutCyclesShowsItsSummaryAndNoPlots) {
  ReportData data;
  data.study_name = "empty";
  data.state = "queued";
  data.objective = std::nan("");
  data.variables.push_back({"x1", "m", 1.0, true, 0.0, 1.0});
  const std::string html = RenderJobReportHtml(data);
  ExpectWellFormedWithCleanCoordinates(html);
  EXPECT_EQ(testing::SvgFragments(html).size(), 0u);
  EXPECT_THAT(html, HasSubstr("No cycle has been recorded for this job yet"));
  EXPECT_THAT(html, HasSubstr("<th>final objective F</th><td>not known</td>"));
}

TEST(JobReportHtml, AStudyWithoutConstraintsGetsNoViolationPlot) {
  ReportData data = testing::SyntheticVehicleReport();
  for (ReportCycle& r : data.records) {
    r.worst_constraint.clear();
    r.max_violation_x0 = 0.0;
    if (std::isfinite(r.max_violation_trial)) r.max_violation_trial = 0.0;
  }
  const std::string html = RenderJobReportHtml(data);
  ExpectWellFormedWithCleanCoordinates(html);
  EXPECT_EQ(testing::SvgFragments(html).size(), 4u);
  EXPECT_THAT(html, HasSubstr("The study has no constraint rows: maxg is 0 throughout"));
}

TEST(JobReportHtml, AJobWithOneCycleDrawsItsPoints) {
  ReportData data = testing::SyntheticVehicleReport();
  data.records.resize(1);
  data.cycles = 1;
  const std::string html = RenderJobReportHtml(data);
  ExpectWellFormedWithCleanCoordinates(html);
  const std::vector<std::string> svgs = testing::SvgFragments(html);
  ASSERT_EQ(svgs.size(), 5u);
  EXPECT_EQ(Count(svgs[0], "<polyline"), 1);  // initial design to cycle 1
  // The move-limit plot has one point per variable: markers, no lines.
  EXPECT_EQ(Count(svgs[3], "<polyline"), 0);
  EXPECT_THAT(svgs[3], Not(HasSubstr("no data to plot")));
}

TEST(JobReportHtml, AFirstTrialThatFailedStillRenders) {
  ReportData data = testing::SyntheticVehicleReport();
  data.records.resize(1);
  ReportCycle& r = data.records[0];
  r.accepted = false;
  r.rejection_reason = "trial analysis failed";
  r.objective_trial = r.max_violation_trial = r.objective_error = r.max_approximation_error = std::nan("");
  data.final_design_physical.clear();
  const std::string html = RenderJobReportHtml(data);
  ExpectWellFormedWithCleanCoordinates(html);
  EXPECT_THAT(html, HasSubstr("No trial point has been accepted: this is the initial design."));
  EXPECT_THAT(html, HasSubstr("No trial point has been accepted, so the rows active"));
  // The final design falls back to x0 of cycle 1: k1 = 10 * 10.
  EXPECT_THAT(DesignRow(html, "k1"), HasSubstr("<td class=\"num\">100</td>"));
}

TEST(JobReportHtml, SurvivesExtremeAndMissingValues) {
  // Every double of every record drawn from awkward values, 200 times over
  // (fixed seed: the same pages every run).
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> awkward = {std::nan(""), inf, -inf, 0.0, -0.0, 1e-300, 1e300, -1e300, 5.0, -3.0};
  std::mt19937 random(20261122);
  std::uniform_int_distribution<std::size_t> pick(0, awkward.size() - 1);
  for (int round = 0; round < 200; ++round) {
    ReportData data = testing::SyntheticVehicleReport();
    auto any = [&]() { return awkward[pick(random)]; };
    for (ReportCycle& r : data.records) {
      for (double* v : {&r.objective_x0, &r.objective_trial, &r.objective_predicted, &r.max_violation_x0,
                        &r.max_violation_trial, &r.objective_error, &r.max_approximation_error}) {
        *v = any();
      }
      for (double& v : r.x0_scaled) v = any();
      for (double& v : r.x_trial_scaled) v = any();
      for (double& v : r.move_limits) v = any();
    }
    data.objective = any();
    data.max_violation = any();
    for (double& v : data.final_design_physical) v = any();
    data.error_scale = round % 3 == 0 ? ScaleChoice::kLog : ScaleChoice::kAuto;
    const std::string html = RenderJobReportHtml(data);
    ExpectWellFormedWithCleanCoordinates(html);
    if (::testing::Test::HasFailure()) {
      ADD_FAILURE() << "round " << round;
      break;
    }
  }
}

}  // namespace
}  // namespace mbopt::report

namespace mbopt::report {
namespace {

// The responses section: a plot per response with both designs and the
// limits as labelled lines, the note under it; without responses, the
// reason.
TEST(JobReportHtml, ShowsResponsesAtTheInitialAndFinalDesignsWithTheirLimits) {
  ReportData data = testing::SyntheticVehicleReport();
  ResponsePlot plot;
  plot.title = "s1: max_abs of s1 <= 0.456 in";
  plot.unit = "in";
  plot.note = "rms: 0.2 in at the initial design";
  plot.times_s = {0.0, 0.5, 1.0};
  plot.initial = {0.0, 0.6, -0.1};
  plot.final = {0.0, 0.4, std::nan("")};
  plot.limits = {{0.456, "limit"}, {-0.456, "-limit"}};
  data.responses = {plot};
  const std::string html = RenderJobReportHtml(data);
  ExpectWellFormedWithCleanCoordinates(html);
  EXPECT_EQ(testing::SvgFragments(html).size(), 6u);
  EXPECT_THAT(html, HasSubstr("Responses at the initial and final designs"));
  EXPECT_THAT(html, HasSubstr("s1: max_abs of s1 &lt;= 0.456 in"));
  EXPECT_THAT(html, HasSubstr("initial design"));
  EXPECT_THAT(html, HasSubstr("final design"));
  EXPECT_THAT(html, HasSubstr("-limit"));
  EXPECT_THAT(html, HasSubstr("rms: 0.2 in at the initial design"));

  data.responses.clear();
  data.responses_note = "The job has no analysed design yet.";
  const std::string none = RenderJobReportHtml(data);
  EXPECT_EQ(testing::SvgFragments(none).size(), 5u);
  EXPECT_THAT(none, HasSubstr("The job has no analysed design yet."));
}

}  // namespace
}  // namespace mbopt::report

namespace mbopt::report {
namespace {

std::string ResponsesSection(const std::string& html) {
  const std::size_t start = html.find("<h2>Responses");
  const std::size_t end = html.find("<h2>Final design</h2>");
  return start == std::string::npos || end == std::string::npos ? "" : html.substr(start, end - start);
}

// A constraint over the window 0.4-0.8 s hands its limit over with that
// window; the plot's reference line carries it.
TEST(JobReportHtml, ALimitIsDrawnOverItsWindowOnly) {
  ResponsePlot plot;
  plot.title = "ram: max of ram_position over 0.4-0.8 s <= 0.1 m";
  plot.times_s = {0.0, 0.5, 1.0};
  plot.initial = {0.0, 0.2, 0.0};
  plot.final = {0.0, 0.1, 0.0};
  plot.limits = {{0.1, "limit", 0.4, 0.8}};
  const PlotSpec spec = ResponsePlotSpec(plot);
  ASSERT_EQ(spec.reference_lines.size(), 1u);
  EXPECT_EQ(spec.reference_lines[0].x_from, 0.4);
  EXPECT_EQ(spec.reference_lines[0].x_to, 0.8);
}

TEST(JobReportHtml, AScalarResponseIsTwoBarsWithTheirValuesNotAPoint) {
  ReportData data = testing::SyntheticVehicleReport();
  ResponsePlot mass;
  mass.title = "mass: final of total_mass <= 12 kg";
  mass.unit = "kg";
  mass.times_s = {1.0};
  mass.initial = {14.5};
  mass.final = {11.25};
  mass.limits = {{12.0, "upper"}};
  data.responses = {mass};
  const std::string section = ResponsesSection(RenderJobReportHtml(data));
  const std::vector<std::string> svgs = testing::SvgFragments(section);
  ASSERT_EQ(svgs.size(), 1u);
  EXPECT_EQ(testing::CheckMarkup(svgs[0], true), "");
  EXPECT_THAT(svgs[0], HasSubstr("scalar-bars"));
  EXPECT_EQ(Count(svgs[0], "<rect"), 2);  // one bar per design
  EXPECT_THAT(svgs[0], HasSubstr(">14.5 kg</text>"));
  EXPECT_THAT(svgs[0], HasSubstr(">11.25 kg</text>"));
  EXPECT_THAT(svgs[0], HasSubstr(">upper 12 kg</text>"));
  EXPECT_THAT(svgs[0], Not(HasSubstr("time [s]")));
  EXPECT_THAT(svgs[0], Not(HasSubstr("<circle")));
}

TEST(JobReportHtml, DrawsTheXyPlotsAskedFor) {
  ReportData data = testing::SyntheticVehicleReport();
  XyPlot xy;
  xy.title = "driver_torque against crank_angle";
  xy.x_label = "crank_angle [deg]";
  xy.y_label = "driver_torque [N m]";
  xy.initial_x = {0, 90, 180, 270};
  xy.initial_y = {1, 3, 2, 1};
  xy.final_x = {0, 90, 180, 270};
  xy.final_y = {1, 2, 1.5, 1};
  data.xy_plots = {xy};
  const std::string html = RenderJobReportHtml(data);
  ExpectWellFormedWithCleanCoordinates(html);
  const std::size_t section = html.find("<h2>Plots of one response against another</h2>");
  ASSERT_NE(section, std::string::npos);
  const std::vector<std::string> svgs = testing::SvgFragments(html.substr(section));
  ASSERT_EQ(svgs.size(), 1u);
  EXPECT_THAT(svgs[0], HasSubstr("driver_torque against crank_angle"));
  EXPECT_THAT(svgs[0], HasSubstr(">crank_angle [deg]</text>"));
  EXPECT_THAT(svgs[0], HasSubstr("driver_torque [N m]"));
  EXPECT_EQ(Count(svgs[0], "<polyline"), 2);

  data.xy_plots.clear();
  EXPECT_THAT(RenderJobReportHtml(data), Not(HasSubstr("against another")));
}

}  // namespace
}  // namespace mbopt::report
