// The study layout and study values on small hand-built studies whose rows
// and values can be written down.
#include "spec/layout.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace mbopt::spec {
namespace {

constexpr double kExact = 1e-15;  // simple arithmetic on exact inputs

// A scene with outputs "a" (acceleration) and "s" (deflection) on a 3-point
// grid 0, 0.5, 1 s.
Study SmallStudy() {
  Study study;
  study.source_file = "small.study.textproto";
  Scene& scene = study.scene;
  scene.model = LumpedModel{};
  Output a;
  a.name = "a";
  a.kind = BodyAccelerationOutput{};
  Output s;
  s.name = "s";
  s.kind = ElementDeflectionOutput{};
  scene.outputs = {a, s};
  scene.time_grid = {0.0, 1.0, 3};
  study.objective.form = Objective::Form::kMinimizeMaxOf;
  study.objective.output = 0;
  study.objective.reduction = Reduction::kMaxAbs;
  Constraint c;
  c.name = "s";
  c.output = 1;
  c.reduction = Reduction::kMaxAbs;
  c.limit = 2.0;
  c.unit = "mm";
  c.si_per_unit = 1e-3;
  study.constraints = {c};
  return study;
}

TEST(StudyLayout, MaxAbsObjectiveHasTwoTermsPerInstantAndConstraintsTwoRows) {
  auto layout = MakeStudyLayout(SmallStudy());
  ASSERT_TRUE(layout.ok()) << layout.status();
  EXPECT_EQ(layout->objective_form, ObjectiveForm::kMinMax);
  EXPECT_EQ(layout->num_objective_terms(), 6);
  ASSERT_EQ(layout->num_constraints(), 6);
  EXPECT_EQ(layout->rows[0].name, "s@t=0.000s upper");
  EXPECT_EQ(layout->rows[1].name, "s@t=0.000s lower");
  EXPECT_EQ(layout->rows[5].name, "s@t=1.000s lower");
  EXPECT_NEAR(layout->rows[0].limit_si, 2e-3, kExact);
  EXPECT_NEAR(layout->rows[1].limit_si, 2e-3, kExact);
  EXPECT_EQ(layout->rows[1].value.sign, -1.0);
  EXPECT_NEAR(layout->rows[3].scale, 2e-3, kExact);
  EXPECT_NEAR(layout->rows[2].time_s, 0.5, kExact);
}

TEST(StudyLayout, MinAndFinalReductions) {
  Study study = SmallStudy();
  study.constraints[0].reduction = Reduction::kMin;
  study.constraints[0].limit = -1.0;
  Constraint final_value = study.constraints[0];
  final_value.name = "end";
  final_value.reduction = Reduction::kFinal;
  final_value.limit = 3.0;
  study.constraints.push_back(final_value);
  auto layout = MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok());
  ASSERT_EQ(layout->num_constraints(), 4);
  // s >= -1 mm  <=>  -s <= 1 mm
  EXPECT_EQ(layout->rows[0].value.sign, -1.0);
  EXPECT_NEAR(layout->rows[0].limit_si, 1e-3, kExact);
  EXPECT_EQ(layout->rows[0].name, "s@t=0.000s lower");
  EXPECT_EQ(layout->rows[3].name, "end@t=1.000s upper");
  EXPECT_EQ(layout->rows[3].value.instant, 2);
}

TEST(StudyLayout, MinimizeMaxOfWithMinReductionIsRejectedNamingTheField) {
  Study study = SmallStudy();
  study.objective.reduction = Reduction::kMin;
  auto layout = MakeStudyLayout(study);
  ASSERT_FALSE(layout.ok());
  EXPECT_THAT(std::string(layout.status().message()),
              ::testing::HasSubstr("small.study.textproto: objective.reduction"));
}

TEST(StudyValues, ObjectiveIsTheLargestTermInTheObjectiveUnitAndWorstRowIsFound) {
  Study study = SmallStudy();
  study.objective.unit = "mm/s^2";
  study.objective.si_per_unit = 1e-3;
  auto layout = MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok());
  const std::vector<std::vector<double>> a = {{1.0, -3.0, 2.0}};
  const std::vector<std::vector<double>> s = {{0.0, 1e-3, -4e-3}};
  auto values = ComputeStudyValues(study, *layout, {&a, &s});
  ASSERT_TRUE(values.ok()) << values.status();
  EXPECT_NEAR(values->objective, 3000.0, 1e-9);  // |-3 m/s^2| in mm/s^2
  ASSERT_EQ(values->objective_terms.size(), 6u);
  EXPECT_NEAR(values->objective_terms[3], 3000.0, 1e-9);  // -f at t = 0.5
  ASSERT_EQ(values->constraint_values.size(), 6u);
  EXPECT_NEAR(values->constraint_values[5], 4e-3, kExact);  // -s at t = 1
  EXPECT_EQ(values->worst_row, 5);
  EXPECT_NEAR(values->max_violation, (4e-3 - 2e-3) / 2e-3, 1e-12);
}

TEST(StudyValues, TargetDistanceUsesFinalValuesInTheTermsUnits) {
  Study study = SmallStudy();
  study.constraints.clear();
  study.objective = Objective{};
  study.objective.form = Objective::Form::kTargetDistance;
  TargetTerm t1;
  t1.output = 1;
  t1.target = 160;
  t1.unit = "mm";
  t1.si_per_unit = 1e-3;
  TargetTerm t2;
  t2.output = 0;
  t2.target = 1.0;
  t2.weight = 5000;
  study.objective.terms = {t1, t2};
  auto layout = MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok());
  EXPECT_EQ(layout->objective_form, ObjectiveForm::kScalar);
  EXPECT_EQ(layout->num_objective_terms(), 1);
  const std::vector<std::vector<double>> a = {{0.0, 0.0, 1.1}};
  const std::vector<std::vector<double>> s = {{0.0, 0.0, 0.163}};
  auto values = ComputeStudyValues(study, *layout, {&a, &s});
  ASSERT_TRUE(values.ok());
  EXPECT_NEAR(values->objective, std::sqrt(3.0 * 3.0 + 5000 * 0.1 * 0.1), 1e-9);
  EXPECT_EQ(values->worst_row, -1);
  EXPECT_EQ(values->max_violation, 0.0);
}

TEST(StudyValues, NaNInAnOutputMakesTheObjectiveNaN) {
  Study study = SmallStudy();
  auto layout = MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok());
  const std::vector<std::vector<double>> a = {{1.0, std::numeric_limits<double>::quiet_NaN(), 2.0}};
  const std::vector<std::vector<double>> s = {{0.0, 0.0, 0.0}};
  auto values = ComputeStudyValues(study, *layout, {&a, &s});
  ASSERT_TRUE(values.ok());
  EXPECT_TRUE(std::isnan(values->objective));
}

TEST(StudyValues, WrongShapeIsRejected) {
  Study study = SmallStudy();
  auto layout = MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok());
  const std::vector<std::vector<double>> a = {{1.0, 2.0}};
  const std::vector<std::vector<double>> s = {{0.0, 0.0, 0.0}};
  auto values = ComputeStudyValues(study, *layout, {&a, &s});
  EXPECT_EQ(values.status().code(), absl::StatusCode::kInvalidArgument);
}

// Reductions over a window (RefValue) against closed forms on a grid.
std::vector<double> Grid(int points) {
  std::vector<double> t(static_cast<size_t>(points));
  for (int i = 0; i < points; ++i) t[static_cast<size_t>(i)] = static_cast<double>(i) / (points - 1);
  return t;
}

ValueRef Over01(Over over, int points, double sign = 1.0) {
  return ValueRef{0, 0, points - 1, sign, over, 0, points - 1};
}

TEST(Reductions, RmsMeanRangeAndIntegralMatchClosedForms) {
  const std::vector<double> t = Grid(1001);
  std::vector<double> f(t.size()), g(t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    f[i] = std::sin(2 * M_PI * t[i]);
    g[i] = t[i] * t[i];
  }
  // sum_i sin^2(2 pi i / 1000) over i = 0..1000 is exactly 500.
  EXPECT_NEAR(RefValue(Over01(Over::kRms, 1001), f, t), std::sqrt(500.0 / 1001.0), 1e-14);
  EXPECT_NEAR(RefValue(Over01(Over::kMean, 1001), g, t), (1000.0 * 1001 * 2001 / 6 / 1e6) / 1001, 1e-14);
  EXPECT_NEAR(RefValue(Over01(Over::kRange, 1001), f, t), 2.0, 1e-14);  // t = 0.25 and 0.75 are instants
  // The trapezoidal rule integrates t^2 with error h^2 / 6 on [0, 1].
  EXPECT_NEAR(RefValue(Over01(Over::kIntegral, 1001), g, t), 1.0 / 3.0 + 1e-6 / 6.0, 1e-14);
  EXPECT_NEAR(RefValue(Over01(Over::kIntegral, 1001, -1.0), g, t), -(1.0 / 3.0 + 1e-6 / 6.0), 1e-14);
  // A window: the mean of t^2 over the instants 0.5 .. 1.0.
  const ValueRef half{0, 0, 1000, 1.0, Over::kMean, 500, 1000};
  double sum = 0;
  for (int i = 500; i <= 1000; ++i) sum += g[static_cast<size_t>(i)];
  EXPECT_NEAR(RefValue(half, g, t), sum / 501, 1e-14);
}

TEST(Reductions, WeightsAreTheDerivativesOfTheValue) {
  const std::vector<double> t = Grid(21);
  std::vector<double> f(t.size());
  for (size_t i = 0; i < t.size(); ++i) f[i] = std::cos(3 * t[i]) + 0.3 * t[i];
  for (Over over : {Over::kRms, Over::kMean, Over::kIntegral, Over::kRange, Over::kInstant}) {
    const ValueRef ref{0, 0, 20, -1.0, over, 3, 17};
    std::vector<double> weights;
    RefValue(ref, f, t, &weights);
    const size_t first = over == Over::kInstant ? 20 : 3;
    for (size_t k = 0; k < weights.size(); ++k) {
      std::vector<double> up = f, down = f;
      const double h = 1e-6;
      up[first + k] += h;
      down[first + k] -= h;
      const double fd = (RefValue(ref, up, t) - RefValue(ref, down, t)) / (2 * h);
      EXPECT_NEAR(weights[k], fd, 1e-8) << static_cast<int>(over) << " k " << k;
    }
  }
}

TEST(StudyLayout, WindowKeepsOnlyItsInstantsAndWholeSeriesReductionsGiveOneRowPerSide) {
  Study study = SmallStudy();
  study.scene.time_grid = {0.0, 1.0, 11};
  study.objective.window.from_s = 0.3;
  study.constraints[0].window = {0.45, 0.75};
  Constraint rms = study.constraints[0];
  rms.name = "rms";
  rms.reduction = Reduction::kRms;
  rms.window = {};
  rms.lower = 1.0;
  rms.upper = 3.0;
  study.constraints.push_back(rms);
  auto layout = MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  EXPECT_EQ(layout->num_objective_terms(), 2 * 8);  // t = 0.3 .. 1.0
  EXPECT_EQ(layout->objective_terms.front().instant, 3);
  ASSERT_EQ(layout->num_constraints(), 2 * 3 + 2);  // t = 0.5, 0.6, 0.7; then rms upper and lower
  EXPECT_NEAR(layout->rows[0].time_s, 0.5, 1e-12);
  EXPECT_EQ(layout->rows[6].name, "rms upper");
  EXPECT_EQ(layout->rows[6].value.over, Over::kRms);
  EXPECT_EQ(layout->rows[6].value.first, 0);
  EXPECT_EQ(layout->rows[6].value.last, 10);
  EXPECT_NEAR(layout->rows[6].limit_si, 3e-3, 1e-15);
  EXPECT_EQ(layout->rows[7].name, "rms lower");
  EXPECT_EQ(layout->rows[7].value.sign, -1.0);
  EXPECT_NEAR(layout->rows[7].limit_si, -1e-3, 1e-15);

  // Values: the RMS of s over the grid, against its bounds.
  std::vector<std::vector<double>> a = {std::vector<double>(11, 0.0)};
  std::vector<std::vector<double>> s = {std::vector<double>(11, 2e-3)};
  auto values = ComputeStudyValues(study, *layout, {&a, &s});
  ASSERT_TRUE(values.ok()) << values.status();
  EXPECT_NEAR(values->constraint_values[6], 2e-3, 1e-15);
  EXPECT_NEAR(values->constraint_values[7], -2e-3, 1e-15);

  study.constraints[0].window = {2.0, 3.0};
  auto empty = MakeStudyLayout(study);
  ASSERT_FALSE(empty.ok());
  EXPECT_THAT(empty.status().message(), ::testing::HasSubstr("constraints[0].window: holds no instant"));
}

TEST(OutputShape, BendingStressHasOneSeriesPerUnpinnedNode) {
  Scene scene;
  LinkageModel linkage;
  linkage.joints.resize(4);
  Link crank;
  crank.joint_a = 0;
  crank.joint_b = 1;
  Link coupler;
  coupler.joint_a = 1;
  coupler.joint_b = 2;
  coupler.flexible_elements = 4;
  linkage.links = {crank, coupler};
  linkage.driver.link = 0;
  linkage.driver.pivot_joint = 0;
  scene.model = linkage;
  Output crank_stress;
  crank_stress.kind = BendingStressOutput{0};
  Output coupler_stress;
  coupler_stress.kind = BendingStressOutput{1};
  scene.outputs = {crank_stress, coupler_stress};
  scene.time_grid = {0.0, 1.0, 5};
  // Rigid crank: 6 stations, nodes 0..6; the driven root (node 0) counts,
  // the pinned tip (node 6) does not.
  const OutputShape crank_shape = OutputShapeOf(scene, 0);
  EXPECT_EQ(crank_shape.series, 6);
  EXPECT_EQ(crank_shape.series_labels.front(), "node 0");
  EXPECT_EQ(crank_shape.series_labels.back(), "node 5");
  // Flexible coupler with 4 elements: interior nodes 1..3.
  EXPECT_EQ(OutputShapeOf(scene, 1).series, 3);
  EXPECT_EQ(OutputShapeOf(scene, 1).instants, 5);
}

TEST(TimeGrid, InstantsAreEquallySpacedAndEndExactly) {
  const TimeGrid grid{0.0, 5.0, 101};
  const std::vector<double> t = grid.Instants();
  ASSERT_EQ(t.size(), 101u);
  EXPECT_EQ(t.front(), 0.0);
  EXPECT_EQ(t.back(), 5.0);  // set exactly, not accumulated
  EXPECT_NEAR(t[35], 1.75, 1e-15);
  EXPECT_EQ(TimeGrid({0.0, 2.0, 1}).Instants(), std::vector<double>{2.0});
}

}  // namespace
}  // namespace mbopt::spec
