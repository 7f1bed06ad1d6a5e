// A sweep's job as its report page's data (client/design_set_report_from_job.h):
// each constraint with one limit is drawn in its unit, its limit where the
// study writes it; the vehicle's sweep (examples/vehicle/vehicle_sweep.
// study.textproto) with its constraints rewritten to each kind of limit.
#include <string>

#include <gtest/gtest.h>

#include "client/design_set_report_from_job.h"
#include "client/study_file.h"
#include "mbopt/v1/service.pb.h"

namespace mbopt::client {
namespace {

std::string VehicleSweep() { return std::string(MBOPT_TEST_SOURCE_DIR) + "/examples/vehicle/vehicle_sweep.study.textproto"; }

v1::GetJobResponse SweepJob(const v1::Study& study) {
  v1::GetJobResponse job;
  *job.mutable_study() = study;
  job.mutable_summary()->set_design_set(true);
  job.mutable_summary()->set_max_cycles(9);
  v1::CycleRecord* r = job.add_cycles();
  r->set_design_set(true);
  r->set_cycle(1);
  for (const v1::DesignVariable& v : study.variables()) {
    job.mutable_summary()->add_design_names(v.name());
    r->add_x_trial_physical(v.initial() * v.scale());
  }
  for (int c = 0; c < study.constraints_size(); ++c) r->add_constraint_violations(-0.25);
  return job;
}

TEST(SweepReportLimits, AMaxAbsLimitIsDrawnInItsUnit) {
  absl::StatusOr<v1::Study> study = ReadStudyForSubmission(VehicleSweep());
  ASSERT_TRUE(study.ok()) << study.status();
  ASSERT_EQ(study->constraints(0).name(), "s1");
  const report::DesignSetReportData data = DesignSetReportFromJob(SweepJob(*study));
  ASSERT_EQ(data.constraints_in_unit.size(), 5u);
  const auto& s1 = data.constraints_in_unit[0];
  EXPECT_TRUE(s1.known);
  EXPECT_EQ(s1.quantity, "|s1|");
  EXPECT_EQ(s1.unit, "in");
  // 0.456 in, through SI and back; the scale is |limit|.
  EXPECT_NEAR(s1.limit, 0.456, 1e-12);
  EXPECT_NEAR(s1.per_normalized, 0.456, 1e-12);
  // A design at -0.25 of the scale lies at 0.75 of the limit.
  EXPECT_NEAR(s1.limit + s1.per_normalized * data.designs[0].constraints[0], 0.342, 1e-12);
  EXPECT_NE(report::RenderDesignSetReportHtml(data).find("limit 0.456 in: above it violated"), std::string::npos);
}

TEST(SweepReportLimits, ALowerLimitReadsAsTheLeastValueViolatedBelow) {
  absl::StatusOr<v1::Study> study = ReadStudyForSubmission(VehicleSweep());
  ASSERT_TRUE(study.ok()) << study.status();
  v1::Constraint* s2 = study->mutable_constraints(1);
  s2->set_reduction(v1::REDUCTION_MIN);
  s2->set_limit(-1.5);
  const report::DesignSetReportData data = DesignSetReportFromJob(SweepJob(*study));
  const auto& in_unit = data.constraints_in_unit[1];
  EXPECT_TRUE(in_unit.known);
  EXPECT_EQ(in_unit.quantity, "s2");
  EXPECT_NEAR(in_unit.limit, -1.5, 1e-12);
  EXPECT_NEAR(in_unit.per_normalized, -1.5, 1e-12);
  EXPECT_NE(report::RenderDesignSetReportHtml(data).find("limit -1.5 in: below it violated"), std::string::npos);
}

TEST(SweepReportLimits, AnEqualityOrATwoSidedBandStaysNormalized) {
  absl::StatusOr<v1::Study> study = ReadStudyForSubmission(VehicleSweep());
  ASSERT_TRUE(study.ok()) << study.status();
  v1::Constraint* s3 = study->mutable_constraints(2);
  s3->set_reduction(v1::REDUCTION_MEAN);
  s3->clear_limit();
  s3->set_lower(-0.5);
  s3->set_upper(0.9);
  v1::Constraint* s4 = study->mutable_constraints(3);
  s4->set_reduction(v1::REDUCTION_FINAL);
  s4->clear_limit();
  s4->set_equals(0);
  s4->set_tolerance(0.05);
  const report::DesignSetReportData data = DesignSetReportFromJob(SweepJob(*study));
  ASSERT_EQ(data.constraints_in_unit.size(), 5u);
  EXPECT_FALSE(data.constraints_in_unit[2].known);
  EXPECT_FALSE(data.constraints_in_unit[3].known);
  EXPECT_TRUE(data.constraints_in_unit[4].known);
}

}  // namespace
}  // namespace mbopt::client
