// The report's analyses of a job (client/report_responses.h) with the real
// mbopt-worker: the x-y plots of the study and of --plot, limits over the
// instants they hold at, every constraint row of the final design, and the
// violation tolerance the server's optimizer uses for the same study. The
// job is made by hand (the vehicle-comfort study at its initial design), so
// no server is needed.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "client/report_responses.h"
#include "server/jobs/problem_from_study.h"
#include "spec/io/study_io.h"

namespace mbopt::client {
namespace {

using ::testing::HasSubstr;

class ReportResponses : public ::testing::Test {
 protected:
  void SetUp() override {
    setenv("MBOPT_WORKER_BIN", MBOPT_TEST_WORKER, 1);
    absl::StatusOr<v1::Study> study =
        spec::io::ReadStudyProto(std::string(MBOPT_TEST_SOURCE_DIR) + "/examples/vehicle/vehicle_comfort.study.textproto");
    ASSERT_TRUE(study.ok()) << study.status();
    v1::Study& s = *job_.mutable_study();
    s = *study;
    // A limit over a window and a bound on the final value, beside the
    // study's limits over the whole grid.
    v1::Constraint* windowed = s.add_constraints();
    windowed->set_name("s2_late");
    windowed->set_output("s2");
    windowed->set_reduction(v1::REDUCTION_MAX);
    windowed->set_limit(2.0);
    windowed->set_unit("in");
    windowed->mutable_window()->set_from_s(1.0);
    windowed->mutable_window()->set_to_s(2.0);
    v1::Constraint* final_value = s.add_constraints();
    final_value->set_name("s1_end");
    final_value->set_output("s1");
    final_value->set_reduction(v1::REDUCTION_FINAL);
    final_value->set_upper(0.3);
    final_value->set_unit("in");
    v1::XyPlot* plot = s.add_plots();
    plot->set_x("s2");
    plot->set_y("seat_acceleration");
    plot->set_x_unit("in");

    // The job stands at its initial design: one accepted cycle record.
    v1::JobSummary& summary = *job_.mutable_summary();
    v1::CycleRecord& record = *job_.add_cycles();
    record.set_cycle(1);
    record.set_accepted(true);
    for (const v1::DesignVariable& v : s.variables()) {
      summary.add_design(v.scale() * v.initial());
      summary.add_design_names(v.name());
      record.add_x0_scaled(v.initial());
      record.add_x_trial_scaled(v.initial());
    }
    absl::StatusOr<spec::Study> loaded = spec::io::StudyFromProto(s, "test");
    ASSERT_TRUE(loaded.ok()) << loaded.status();
    study_ = *loaded;
  }

  v1::GetJobResponse job_;
  spec::Study study_;
};

TEST_F(ReportResponses, ToleranceIsTheOptimizersForTheSameStudy) {
  EXPECT_EQ(ViolationToleranceOf(study_), jobs::SlpOptionsFromStudy(study_)->convergence_violation_tolerance);
  // The settled-seat band made narrow (+-0.001 in) narrows the default: the
  // check is not vacuous.
  for (spec::Constraint& c : study_.constraints) {
    if (c.equals) c.lower = *c.equals - 0.001, c.upper = *c.equals + 0.001;
  }
  absl::StatusOr<slp::SlpOptions> options = jobs::SlpOptionsFromStudy(study_);
  ASSERT_TRUE(options.ok()) << options.status();
  EXPECT_LT(options->convergence_violation_tolerance, report::kDefaultViolationTolerance);
  EXPECT_EQ(ViolationToleranceOf(study_), options->convergence_violation_tolerance);
  study_.optimizer.convergence_violation_tolerance = 0.02;
  EXPECT_EQ(ViolationToleranceOf(study_), jobs::SlpOptionsFromStudy(study_)->convergence_violation_tolerance);
}

TEST_F(ReportResponses, DrawsTheStudysAndTheCommandLinesXyPlots) {
  report::ReportData data;
  ASSERT_TRUE(AddResponsePlots(job_, {"s1:s5"}, &data).ok());
  ASSERT_EQ(data.xy_plots.size(), 2u) << data.responses_note;
  const report::XyPlot& study_plot = data.xy_plots[0];
  EXPECT_EQ(study_plot.title, "seat_acceleration against s2");
  EXPECT_EQ(study_plot.x_label, "s2 [in]");
  EXPECT_EQ(study_plot.y_label, "seat_acceleration [m/s^2]");
  const std::size_t instants = static_cast<std::size_t>(study_.scene.time_grid.points);
  EXPECT_EQ(study_plot.initial_x.size(), instants);
  EXPECT_EQ(study_plot.final_y.size(), instants);
  EXPECT_EQ(data.xy_plots[1].title, "s5 against s1");
  EXPECT_EQ(data.xy_plots[1].x_label, "s1 [m]");  // no unit asked: SI
  // The x axis in inches: the deflection's largest magnitude is a fraction
  // of an inch to a few inches, not of a metre.
  double largest = 0;
  for (double v : study_plot.final_x) largest = std::max(largest, std::abs(v));
  EXPECT_GT(largest, 0.05);
}

TEST_F(ReportResponses, LimitsCarryTheInstantsTheyHoldAt) {
  report::ReportData data;
  ASSERT_TRUE(AddResponsePlots(job_, {}, &data).ok());
  auto plot_of = [&](const std::string& name) -> const report::ResponsePlot* {
    for (const report::ResponsePlot& p : data.responses) {
      if (p.title.rfind(name + ":", 0) == 0) return &p;
    }
    return nullptr;
  };
  const report::ResponsePlot* whole = plot_of("s1");
  const report::ResponsePlot* windowed = plot_of("s2_late");
  const report::ResponsePlot* final_value = plot_of("s1_end");
  ASSERT_NE(whole, nullptr);
  ASSERT_NE(windowed, nullptr);
  ASSERT_NE(final_value, nullptr);
  ASSERT_EQ(whole->limits.size(), 2u);
  EXPECT_TRUE(std::isinf(whole->limits[0].from_s) && std::isinf(whole->limits[0].to_s));
  ASSERT_EQ(windowed->limits.size(), 1u);
  EXPECT_EQ(windowed->limits[0].from_s, 1.0);
  EXPECT_EQ(windowed->limits[0].to_s, 2.0);
  ASSERT_EQ(final_value->limits.size(), 1u);
  EXPECT_EQ(final_value->limits[0].from_s, final_value->limits[0].to_s);
  EXPECT_EQ(final_value->limits[0].from_s, final_value->times_s.back());
}

TEST_F(ReportResponses, ListsEveryRowOfTheFinalDesignAboveTheThreshold) {
  report::ReportData data;
  ASSERT_TRUE(AddResponsePlots(job_, {}, &data).ok());
  EXPECT_TRUE(data.active_constraints_complete);
  ASSERT_FALSE(data.active_constraints.empty());
  // Rows above the threshold, and the most critical row even when below.
  int below = 0;
  for (const report::ActiveConstraint& a : data.active_constraints) {
    EXPECT_FALSE(a.name.empty());
    below += a.normalized_value > report::kActiveThreshold ? 0 : 1;
  }
  EXPECT_LE(below, data.active_constraints.size() == 1 ? 1 : 0);
}

TEST_F(ReportResponses, AnUnknownPlotNameIsRefusedWithTheNamesThatExist) {
  report::ReportData data;
  const absl::Status bad = AddResponsePlots(job_, {"s1:crank_angle"}, &data);
  EXPECT_EQ(bad.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(bad.message(), HasSubstr("--plot s1:crank_angle: unknown output \"crank_angle\""));
  EXPECT_THAT(bad.message(), HasSubstr("\"seat_acceleration\", \"s1\""));
  const absl::Status malformed = AddResponsePlots(job_, {"s1"}, &data);
  EXPECT_THAT(malformed.message(), HasSubstr("expected X:Y"));
}

}  // namespace
}  // namespace mbopt::client
