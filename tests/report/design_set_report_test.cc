// The report page of a sweep or sample (client/report/design_set_report.h):
// well formed, one plot of the objective and one per constraint against the
// swept variable (a grid: a curve per value of its second variable), the
// limit drawn, failed designs marked and left out of the curves.
#include "client/report/design_set_report.h"

#include <cmath>

#include <gtest/gtest.h>

#include "tests/report/markup_checker.h"

namespace mbopt::report {
namespace {

// k swept over 5 designs (the third failed), c held; constraints "travel"
// (violated above k = 300) and "stroke".
DesignSetReportData LineSweep() {
  DesignSetReportData data;
  data.job_id = "job-7";
  data.study_name = "a <sweep>";
  data.state = "completed";
  data.objective_unit = "m/s^2";
  data.designs_total = 5;
  data.variable_names = {"k", "c"};
  data.variable_units = {"N/m", "N s/m"};
  data.swept = {0};
  data.constraint_names = {"travel", "stroke"};
  for (int i = 0; i < 5; ++i) {
    DesignSetReportData::Design d;
    d.index = i + 1;
    d.values = {100.0 + 100.0 * i, 20.0};
    if (i == 2) {
      d.objective = d.max_violation = std::nan("");
      d.constraints = {std::nan(""), std::nan("")};
      d.status = "integrator";
      d.failure_reason = "step size too small";
    } else {
      d.objective = 5.0 - i;
      d.constraints = {-0.2 + 0.1 * i, -0.5};
      d.max_violation = std::max(d.constraints[0], d.constraints[1]);
      d.status = "ok";
    }
    data.designs.push_back(d);
  }
  return data;
}

TEST(DesignSetReport, IsWellFormedWithAPlotOfTheObjectiveAndOnePerConstraint) {
  const std::string html = RenderDesignSetReportHtml(LineSweep());
  EXPECT_EQ(testing::CheckMarkup(html, /*xml_strict=*/false), "");
  const std::vector<std::string> svgs = testing::SvgFragments(html);
  ASSERT_EQ(svgs.size(), 3u);
  for (const std::string& svg : svgs) EXPECT_EQ(testing::CheckMarkup(svg, /*xml_strict=*/true), "");
  EXPECT_NE(svgs[0].find("Objective F against k"), std::string::npos);
  EXPECT_NE(svgs[0].find("k [N/m]"), std::string::npos);
  EXPECT_NE(svgs[1].find("Constraint travel against k"), std::string::npos);
  EXPECT_NE(svgs[1].find("limit: above it violated"), std::string::npos);
  EXPECT_NE(svgs[2].find("Constraint stroke against k"), std::string::npos);
  for (const char* nan : {"\"nan", "nan\"", ">nan", " nan", ",nan"}) {
    EXPECT_EQ(html.find(nan), std::string::npos) << "a failed design leaves a gap, not a NaN: " << nan;
  }
  EXPECT_NE(html.find("a &lt;sweep&gt;"), std::string::npos);
  EXPECT_EQ(html.find("a <sweep>"), std::string::npos);
}

// "travel" read in millimetres with its limit at 10 mm (scale 10 mm); the
// lower limit "stroke" at 2 mm; a constraint without a unit reading stays
// normalized.
TEST(DesignSetReport, DrawsEachConstraintInItsUnitWithItsLimitThere) {
  DesignSetReportData data = LineSweep();
  data.constraint_names.push_back("band");
  for (auto& d : data.designs) d.constraints.push_back(0.0);
  data.constraints_in_unit = {{true, "|travel|", "mm", 10.0, 10.0}, {true, "stroke", "mm", 2.0, -2.0}, {}};
  const std::vector<std::string> svgs = testing::SvgFragments(RenderDesignSetReportHtml(data));
  ASSERT_EQ(svgs.size(), 4u);
  EXPECT_NE(svgs[1].find("|travel| [mm]"), std::string::npos);
  EXPECT_NE(svgs[1].find("limit 10 mm: above it violated"), std::string::npos);
  EXPECT_EQ(svgs[1].find("(g - limit) / scale"), std::string::npos);
  EXPECT_NE(svgs[2].find("stroke [mm]"), std::string::npos);
  EXPECT_NE(svgs[2].find("limit 2 mm: below it violated"), std::string::npos);
  EXPECT_NE(svgs[3].find("(g - limit) / scale"), std::string::npos);
  EXPECT_NE(svgs[3].find("limit: above it violated"), std::string::npos);
  // travel's normalized -0.2 .. 0.1 is 8 .. 11 mm: the axis reaches 11, not 0.1.
  EXPECT_NE(svgs[1].find(">11<"), std::string::npos) << svgs[1];
}

TEST(DesignSetReport, TableMarksFailedDesignsAndViolatedValues) {
  const std::string html = RenderDesignSetReportHtml(LineSweep());
  EXPECT_EQ(testing::CountOccurrences(html, "<tr class=\"failed\">"), 1);
  EXPECT_NE(html.find("integrator: step size too small"), std::string::npos);
  // Designs 4 and 5 violate travel (0.1, 0.2): each value and its maxg.
  EXPECT_EQ(testing::CountOccurrences(html, "class=\"num violated\""), 4) << html;
  EXPECT_NE(html.find("<tr><th>designs analysed</th><td>5 of 5</td></tr>"), std::string::npos);
}

TEST(DesignSetReport, GridDrawsACurvePerValueOfTheSecondVariable) {
  DesignSetReportData data = LineSweep();
  data.swept = {0, 1};
  data.designs.clear();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 2; ++j) {
      DesignSetReportData::Design d;
      d.index = 2 * i + j + 1;
      d.values = {100.0 * (i + 1), 10.0 * (j + 1)};
      d.objective = i + j;
      d.constraints = {-0.1, -0.2};
      d.max_violation = -0.1;
      d.status = "ok";
      data.designs.push_back(d);
    }
  }
  const std::vector<std::string> svgs = testing::SvgFragments(RenderDesignSetReportHtml(data));
  ASSERT_EQ(svgs.size(), 3u);
  EXPECT_NE(svgs[0].find("c = 10"), std::string::npos) << svgs[0];
  EXPECT_NE(svgs[0].find("c = 20"), std::string::npos) << svgs[0];
  EXPECT_EQ(testing::CountOccurrences(svgs[0], "<polyline"), 2) << svgs[0];
}

TEST(DesignSetReport, SamplePlotsTheObjectiveAgainstEachVariableAsPoints) {
  DesignSetReportData data = LineSweep();
  data.swept.clear();
  const std::vector<std::string> svgs = testing::SvgFragments(RenderDesignSetReportHtml(data));
  ASSERT_EQ(svgs.size(), 2u);
  EXPECT_NE(svgs[0].find("Objective F against k"), std::string::npos);
  EXPECT_NE(svgs[1].find("Objective F against c"), std::string::npos);
  EXPECT_EQ(testing::CountOccurrences(svgs[0], "<polyline"), 0) << "a sample's designs are not a curve";
}

}  // namespace
}  // namespace mbopt::report
