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

using spec::AnalysisReport;
using spec::Formulation;
using spec::FormulationName;
using spec::OutputValues;

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
  EXPECT_STREQ(FormulationName(Formulation::kStatic), "static");
}

TEST(Engine, LumpedSceneIsADynamicAnalysisWithCountersAndWallTime) {
  const spec::Study study = Vehicle();
  const AnalysisReport r = Analyze(study.scene, study.scene.DefaultParameterValues());
  ASSERT_TRUE(r.ok()) << r.failure.reason;
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
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_THAT(r.failure.reason, HasSubstr("parameter values"));
}

TEST(Engine, AnalysesAreDeterministic) {
  const spec::Study study = Vehicle();
  const auto p = study.scene.DefaultParameterValues();
  const AnalysisReport a = Analyze(study.scene, p);
  const AnalysisReport b = Analyze(study.scene, p);
  ASSERT_TRUE(a.ok());
  // Bit identity is the point: resumed optimizations replay analyses.
  EXPECT_EQ(a.outputs[0].series, b.outputs[0].series);
}

TEST(StudyValuesOfReport, FailedAnalysisIsFailedPreconditionWithItsReason) {
  const spec::Study study = Vehicle();
  auto layout = spec::MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok());
  AnalysisReport failed;
  failed.Fail(spec::FailureKind::kIntegrator, "integrator failed near t = 1");
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

// A stress output may report every node; the layout's nodes are picked by
// label (interior nodes of a rigid, undriven link: 1..5 of 0..6).
TEST(StudyValuesOfReport, ExtraSeriesArePickedByLabel) {
  spec::Study study;
  spec::LinkageModel linkage;
  linkage.joints.resize(3);
  spec::Link link;
  link.joint_a = 1;
  link.joint_b = 2;
  linkage.links = {link};
  linkage.driver.link = -1;
  study.scene.model = linkage;
  spec::Output stress;
  stress.name = "stress";
  stress.kind = spec::BendingStressOutput{0};
  study.scene.outputs = {stress};
  study.scene.time_grid = {0.0, 1.0, 2};
  study.objective.form = spec::Objective::Form::kMinimizeMaxOf;
  study.objective.output = 0;
  study.objective.reduction = spec::Reduction::kMax;
  auto layout = spec::MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  ASSERT_EQ(layout->outputs[0].series, 5);
  AnalysisReport r;
  r.times_s = {0.0, 1.0};
  OutputValues v;
  v.name = "stress";
  for (int node = 0; node <= 6; ++node) {
    v.series_labels.push_back("node " + std::to_string(node));
    v.series.push_back({1.0 * node, 10.0 * node});
  }
  r.outputs = {v};
  auto values = ComputeStudyValues(study, *layout, r);
  ASSERT_TRUE(values.ok()) << values.status();
  ASSERT_EQ(values->objective_terms.size(), 10u);
  EXPECT_DOUBLE_EQ(values->objective_terms[0], 1.0);  // node 1 at t = 0
  EXPECT_DOUBLE_EQ(values->objective, 50.0);          // node 5 at t = 1, not node 6
  r.outputs[0].series_labels[3] = "node x";
  EXPECT_EQ(ComputeStudyValues(study, *layout, r).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace mbopt::engine
