// The page says one thing about one design: the header's final design is
// the one the active-constraint table and every "violated" mark describe,
// and a value inside the SLP's convergence tolerance is not called violated.
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "client/report/job_report_html.h"
#include "client/report/report_tables.h"
#include "server/slp/options.h"
#include "tests/report/synthetic_report.h"

namespace mbopt::report {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// The report cannot link the optimizer (the client is kept apart from the
// server), so it carries its own copy of the default: this keeps them equal.
TEST(ReportConsistency, DefaultToleranceIsTheSlpDefault) {
  EXPECT_EQ(kDefaultViolationTolerance, slp::SlpOptions{}.convergence_violation_tolerance);
}

std::string ActiveSection(const std::string& html) {
  const std::size_t start = html.find("<h2>Active constraints</h2>");
  const std::size_t end = html.find("<h2>Cycles</h2>");
  return start == std::string::npos || end == std::string::npos ? "" : html.substr(start, end - start);
}

TEST(ReportConsistency, AConvergedDesignWithinTheToleranceIsNotCalledViolated) {
  ReportData data = testing::SyntheticVehicleReport();  // converged, maxg 0.00025
  const std::string html = RenderJobReportHtml(data);
  EXPECT_THAT(html, Not(HasSubstr("(violated)")));
  EXPECT_THAT(html, HasSubstr("<th>max violation maxg</th><td>0.00025 (within the tolerance 0.005)</td>"));
  EXPECT_THAT(ActiveSection(html), HasSubstr("<td>within the tolerance 0.005</td>"));
}

TEST(ReportConsistency, AViolationAboveTheToleranceIsCalledViolated) {
  ReportData data = testing::SyntheticVehicleReport();
  data.max_violation = 0.02;
  data.records.back().max_violation_trial = 0.02;
  const std::string html = RenderJobReportHtml(data);
  EXPECT_THAT(html, HasSubstr("<th>max violation maxg</th><td>0.02 (violated)</td>"));
  EXPECT_THAT(ActiveSection(html), HasSubstr("<td>violated</td>"));
}

TEST(ReportConsistency, TheStudysOwnToleranceDecides) {
  ReportData data = testing::SyntheticVehicleReport();
  data.violation_tolerance = 1e-4;  // the study set a tighter one
  const std::string html = RenderJobReportHtml(data);
  EXPECT_THAT(html, HasSubstr("<th>max violation maxg</th><td>0.00025 (violated)</td>"));
  EXPECT_THAT(html, HasSubstr("0.0001 converged below"));  // the violation plot's line
}

// The best design the server reports need not be the last accepted trial:
// here the run ends on a worse design (cycle 11 accepts a trial with a
// violated row), while the header's design is the trial of cycle 9.
ReportData EndsAfterItsBestDesign() {
  ReportData data = testing::SyntheticVehicleReport();
  ReportCycle& best = data.records[data.records.size() - 3];  // cycle 9
  ReportCycle& last = data.records.back();                     // cycle 11
  best.worst_constraint = "rear_wheel_road@t=0.100s lower";
  best.max_violation_trial = -0.001;
  last.worst_constraint = "seat_chassis@t=0.420s upper";
  last.max_violation_trial = 0.03;
  for (double& x : last.x_trial_scaled) x *= 1.01;
  data.max_violation = best.max_violation_trial;
  data.final_design_physical.clear();
  for (std::size_t i = 0; i < best.x_trial_scaled.size(); ++i) {
    data.final_design_physical.push_back(data.variables[i].scale * best.x_trial_scaled[i]);
  }
  return data;
}

TEST(ReportConsistency, ActiveTableDescribesTheHeadersDesignNotTheLastTrial) {
  const ReportData data = EndsAfterItsBestDesign();
  ASSERT_EQ(RecordOfFinalDesign(data), &data.records[data.records.size() - 3]);
  const std::string active = ActiveSection(RenderJobReportHtml(data));
  EXPECT_THAT(active, HasSubstr("<td>rear_wheel_road@t=0.100s lower</td>"));
  EXPECT_THAT(active, HasSubstr("trial point of cycle 9"));
  EXPECT_THAT(active, Not(HasSubstr("seat_chassis")));
  EXPECT_THAT(active, Not(HasSubstr("violated")));
}

TEST(ReportConsistency, AFinalDesignNoRecordHoldsIsSaidToBeUnrecorded) {
  ReportData data = testing::SyntheticVehicleReport();
  for (double& v : data.final_design_physical) v *= 3.0;  // e.g. the initial design
  EXPECT_EQ(RecordOfFinalDesign(data), nullptr);
  const std::string active = ActiveSection(RenderJobReportHtml(data));
  EXPECT_THAT(active, HasSubstr("No cycle record has the final design as its trial point"));
  EXPECT_THAT(active, Not(HasSubstr("<table")));
}

// With every row of an analysis of the final design the table lists all
// active ones, most critical first, and nothing from the records.
TEST(ReportConsistency, RowsOfTheFinalAnalysisReplaceTheRecordsGuess) {
  ReportData data = EndsAfterItsBestDesign();
  data.active_constraints = {{"a@t=0.1s upper", -0.3},
                             {"b@t=0.2s upper", -0.004},
                             {"c@t=0.3s lower", 0.003},
                             {"d@t=0.4s lower", -0.001}};
  data.active_constraints_complete = true;
  const std::string active = ActiveSection(RenderJobReportHtml(data));
  EXPECT_THAT(active, Not(HasSubstr("a@")));
  const std::size_t c = active.find("c@"), d = active.find("d@"), b = active.find("b@");
  ASSERT_NE(c, std::string::npos);
  ASSERT_NE(d, std::string::npos);
  ASSERT_NE(b, std::string::npos);
  EXPECT_LT(c, d);
  EXPECT_LT(d, b);
  EXPECT_THAT(active, HasSubstr("analysis of the final design"));
  EXPECT_THAT(active, Not(HasSubstr("rear_wheel_road")));
  EXPECT_THAT(active, Not(HasSubstr("keeps only the most critical row")));

  data.active_constraints = {{"a@t=0.1s upper", -0.3}};
  const std::string none = ActiveSection(RenderJobReportHtml(data));
  EXPECT_THAT(none, HasSubstr("No row is active at the final design: the most critical, a@t=0.1s upper"));
}

}  // namespace
}  // namespace mbopt::report
