// The engine's entry point: it dispatches a scene to its formulation, times
// the analysis on the caller's clock, and turns bad parameter vectors into failed analyses; and
// the study values of an engine report.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/monotonic_clock.h"
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
  // The wall time is read on the caller's clock, here the process' own.
  const AnalysisReport r = Analyze(study.scene, study.scene.DefaultParameterValues(), nullptr,
                                   budget::AnalysisBudget(&MonotonicSeconds, nullptr));
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
  auto values = ComputeStudyValues(study, *layout, failed, study.scene.DefaultParameterValues());
  EXPECT_EQ(values.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(std::string(values.status().message()), HasSubstr("integrator failed near t = 1"));
}

TEST(StudyValuesOfReport, VehicleInitialDesignViolatesTheSeatTravelLimitAboutFourfold) {
  const spec::Study study = Vehicle();
  auto layout = spec::MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok());
  const AnalysisReport r = Analyze(study.scene, study.scene.DefaultParameterValues());
  auto values = ComputeStudyValues(study, *layout, r, study.scene.DefaultParameterValues());
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
  auto values = ComputeStudyValues(study, *layout, r, study.scene.DefaultParameterValues());
  ASSERT_TRUE(values.ok()) << values.status();
  ASSERT_EQ(values->objective_terms.size(), 10u);
  EXPECT_DOUBLE_EQ(values->objective_terms[0], 1.0);  // node 1 at t = 0
  EXPECT_DOUBLE_EQ(values->objective, 50.0);          // node 5 at t = 1, not node 6
  r.outputs[0].series_labels[3] = "node x";
  EXPECT_EQ(ComputeStudyValues(study, *layout, r, study.scene.DefaultParameterValues()).status().code(),
            absl::StatusCode::kInvalidArgument);
}

// Load cases: one report holding every case's outputs in signal order,
// each case's outputs bit for bit those of an analysis at its parameters,
// counters summed; a failing case fails the report and is named.
TEST(Engine, LoadCasesAreAnalysedOneAfterTheOther) {
  auto study = spec::io::LoadStudyFile("examples/vehicle/vehicle_two_roads.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  ASSERT_EQ(study->num_cases(), 2);
  std::vector<double> x;
  for (const spec::DesignVariable& v : study->variables) x.push_back(v.initial);
  const std::vector<double> design = study->ParameterValuesAt(x);
  const AnalysisReport combined = AnalyzeCases(*study, design);
  ASSERT_TRUE(combined.ok()) << combined.failure.reason;
  const size_t outputs = study->scene.outputs.size();
  ASSERT_EQ(combined.outputs.size(), 2 * outputs);
  spec::AnalysisCounters sum;
  for (int c = 0; c < 2; ++c) {
    const AnalysisReport alone = Analyze(study->scene, study->CaseParameterValues(c, design));
    ASSERT_TRUE(alone.ok());
    sum += alone.counters;
    for (size_t o = 0; o < outputs; ++o) {
      const OutputValues& got = combined.outputs[static_cast<size_t>(c) * outputs + o];
      EXPECT_EQ(got.name, study->SignalName(static_cast<int>(static_cast<size_t>(c) * outputs + o)));
      EXPECT_EQ(got.series, alone.outputs[o].series) << got.name;
    }
  }
  EXPECT_EQ(combined.counters.time_steps, sum.time_steps);
  EXPECT_EQ(combined.counters.rhs_evaluations, sum.rhs_evaluations);
  // The two roads differ.
  EXPECT_NE(combined.outputs[0].series, combined.outputs[outputs].series);

  spec::Study failing = *study;
  failing.cases[1].parameter_values_si.emplace_back(failing.scene.FindParameter("m1"), -1.0);
  const AnalysisReport failed = AnalyzeCases(failing, design);
  ASSERT_FALSE(failed.ok());
  EXPECT_THAT(failed.failure.reason, HasSubstr("load case fast: "));
  EXPECT_TRUE(failed.outputs.empty());
}

}  // namespace
}  // namespace mbopt::engine
