// The engine's entry point: it dispatches a scene to its formulation, times
// the analysis, and turns bad parameter vectors into failed analyses; and
// the study values of an engine report.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "worker/engine/analysis.h"
#include "worker/engine/study_values.h"

namespace mbopt::engine {
namespace {

using ::testing::HasSubstr;

spec::Study Vehicle() {
  auto study = spec::io::LoadStudyFile("examples/vehicle/vehicle.study.textproto");
  EXPECT_TRUE(study.ok()) << study.status();
  return *std::move(study);
}

TEST(Engine, FormulationNamesAreStable) {
  EXPECT_STREQ(FormulationName(Formulation::kKinematic), "kinematic");
  EXPECT_STREQ(FormulationName(Formulation::kKinetostatic), "kinetostatic");
  EXPECT_STREQ(FormulationName(Formulation::kDynamic), "dynamic");
  EXPECT_STREQ(FormulationName(Formulation::kElastodynamic), "elastodynamic");
}

TEST(Engine, LumpedSceneIsADynamicAnalysisWithCountersAndWallTime) {
  const spec::Study study = Vehicle();
  const AnalysisReport r = Analyze(study.scene, study.scene.DefaultParameterValues());
  ASSERT_EQ(r.status, AnalysisStatus::kOk) << r.failure_reason;
  EXPECT_EQ(r.formulation, Formulation::kDynamic);
  EXPECT_EQ(r.times_s.size(), 101u);
  EXPECT_GT(r.counters.time_steps, 0);
  EXPECT_GT(r.counters.rhs_evaluations, 0);
  EXPECT_GT(r.counters.jacobian_evaluations, 0);
  EXPECT_GT(r.counters.newton_iterations, 0);
  EXPECT_EQ(r.counters.position_solves, 0);
  EXPECT_GT(r.counters.wall_seconds, 0.0);
}

TEST(Engine, WrongNumberOfParameterValuesIsAFailedAnalysis) {
  const spec::Study study = Vehicle();
  const AnalysisReport r = Analyze(study.scene, {1.0, 2.0});
  EXPECT_EQ(r.status, AnalysisStatus::kFailed);
  EXPECT_THAT(r.failure_reason, HasSubstr("parameter values"));
}

TEST(Engine, AnalysesAreDeterministic) {
  const spec::Study study = Vehicle();
  const auto p = study.scene.DefaultParameterValues();
  const AnalysisReport a = Analyze(study.scene, p);
  const AnalysisReport b = Analyze(study.scene, p);
  ASSERT_EQ(a.status, AnalysisStatus::kOk);
  // Bit identity is the point: resumed optimizations replay analyses.
  EXPECT_EQ(a.outputs[0].series, b.outputs[0].series);
}

TEST(StudyValuesOfReport, FailedAnalysisIsFailedPreconditionWithItsReason) {
  const spec::Study study = Vehicle();
  auto layout = spec::MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok());
  AnalysisReport failed;
  failed.status = AnalysisStatus::kFailed;
  failed.failure_reason = "integrator failed near t = 1";
  auto values = ComputeStudyValues(study, *layout, failed);
  EXPECT_EQ(values.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(std::string(values.status().message()), HasSubstr("integrator failed near t = 1"));
}

TEST(StudyValuesOfReport, VehicleInitialDesignViolatesTheSeatTravelLimitAboutFourfold) {
  const spec::Study study = Vehicle();
  auto layout = spec::MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok());
  const AnalysisReport r = Analyze(study.scene, study.scene.DefaultParameterValues());
  auto values = ComputeStudyValues(study, *layout, r);
  ASSERT_TRUE(values.ok()) << values.status();
  ASSERT_GE(values->worst_row, 0);
  EXPECT_THAT(layout->rows[static_cast<size_t>(values->worst_row)].name, HasSubstr("s1@"));
  // max |s1| = 1.8332 in against 0.456 in: g/c - 1 = 3.02.
  EXPECT_NEAR(values->max_violation, 1.8332 / 0.456 - 1.0, 1e-3);
}

}  // namespace
}  // namespace mbopt::engine
