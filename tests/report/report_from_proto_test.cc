#include "client/report/report_from_proto.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "client/report/job_report_html.h"

namespace mbopt::report {
namespace {

using ::testing::HasSubstr;

// Values pass through the conversion unchanged: no arithmetic on them.
v1::GetJobResponse SampleJob() {
  v1::GetJobResponse job;
  v1::JobSummary* s = job.mutable_summary();
  s->set_job_id("j1");
  s->set_study_name("fourbar");
  s->set_state(v1::JOB_STATE_MAX_CYCLES);
  s->set_cycles(1);
  s->set_analyses(5);
  s->set_objective(2.36);
  s->set_objective_unit("kg");
  s->set_max_violation(-0.01);
  s->add_design_names("A1");
  s->add_design_units("m^2");
  s->add_design(9.65e-4);
  v1::DesignVariable* v = job.mutable_study()->add_variables();
  v->set_name("A1");
  v->set_scale(1e-3);
  v->set_lower(0.1);
  v->set_upper(100);
  v1::CycleRecord* r = job.add_cycles();
  r->set_cycle(1);
  r->set_attempt(0);
  r->set_accepted(true);
  r->add_x0_scaled(100);
  r->add_x_trial_scaled(0.965);
  r->set_objective_x0(546);
  r->set_objective_trial(2.36);
  r->set_max_violation_trial(-0.01);
  r->set_worst_constraint("stress[crank]@t=0.350s upper");
  r->set_max_approximation_error(0.08);
  r->set_objective_error(std::nan(""));
  r->set_lp_feasible(true);
  r->add_move_limits(0.2);
  r->set_analyses_total(5);
  return job;
}

TEST(ReportFromProto, CarriesSummaryVariablesAndRecords) {
  const ReportData d = ReportDataFromJob(SampleJob());
  EXPECT_EQ(d.job_id, "j1");
  EXPECT_EQ(d.study_name, "fourbar");
  EXPECT_EQ(d.state, "max_cycles");
  EXPECT_EQ(d.objective_unit, "kg");
  ASSERT_EQ(d.variables.size(), 1u);
  EXPECT_EQ(d.variables[0].unit, "m^2");
  EXPECT_TRUE(d.variables[0].has_bounds);
  EXPECT_EQ(d.variables[0].scale, 1e-3);
  EXPECT_EQ(d.variables[0].upper_scaled, 100);
  ASSERT_EQ(d.final_design_physical.size(), 1u);
  ASSERT_EQ(d.records.size(), 1u);
  EXPECT_EQ(d.records[0].worst_constraint, "stress[crank]@t=0.350s upper");
  EXPECT_TRUE(std::isnan(d.records[0].objective_error));
  EXPECT_EQ(d.records[0].move_limits, std::vector<double>{0.2});
}

TEST(ReportFromProto, ZeroScaleMeansOne) {
  v1::GetJobResponse job = SampleJob();
  job.mutable_study()->mutable_variables(0)->set_scale(0);
  EXPECT_EQ(ReportDataFromJob(job).variables[0].scale, 1.0);
}

TEST(ReportFromProto, WithoutAStudyTheBoundsAreUnknown) {
  v1::GetJobResponse job = SampleJob();
  job.clear_study();
  const ReportData d = ReportDataFromJob(job);
  ASSERT_EQ(d.variables.size(), 1u);
  EXPECT_FALSE(d.variables[0].has_bounds);
  EXPECT_THAT(RenderJobReportHtml(d), HasSubstr("bounds unknown"));
}

TEST(ReportFromProto, AJobWithoutRecordsHasNoObjectiveYet) {
  v1::GetJobResponse job = SampleJob();
  job.clear_cycles();
  job.mutable_summary()->set_objective(0);
  job.mutable_summary()->set_max_violation(0);
  const ReportData d = ReportDataFromJob(job);
  EXPECT_TRUE(std::isnan(d.objective));
  EXPECT_TRUE(std::isnan(d.max_violation));
  const std::string html = RenderJobReportHtml(d);
  EXPECT_THAT(html, HasSubstr("<th>final objective F</th><td>not known kg</td>"));
}

TEST(ReportFromProto, RendersTheConvertedJob) {
  const std::string html = RenderJobReportHtml(ReportDataFromJob(SampleJob()));
  EXPECT_THAT(html, HasSubstr("<h1>fourbar</h1>"));
  EXPECT_THAT(html, HasSubstr("2.36 kg"));
}

}  // namespace
}  // namespace mbopt::report
