// The study language as a user writes it: equality bands and their row
// scales, studies without an objective, parameters as expressions, units
// engineers write and the messages that say what to write instead.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "spec/layout.h"
#include "tests/spec/oscillator_scene.h"

namespace mbopt::spec::io {
namespace {

using ::testing::HasSubstr;

const char kStudyHead[] = R"pb(name: "oscillator study"
scene_file: "oscillator.scene.textproto"
variables { name: "x1" parameter: "k" scale: 10 lower: 5 upper: 20 }
)pb";

const char kPeakObjective[] = "objective { minimize_max_of: \"acc\" reduction: REDUCTION_MAX_ABS }\n";

class StudyLanguage : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    dir_ = std::filesystem::path(::testing::TempDir()) / ("study_language_" + test);
    std::filesystem::create_directories(dir_);
  }
  absl::StatusOr<Study> Load(const std::string& study, const std::string& scene = ::mbopt::testing::kOscillatorScene) {
    std::ofstream(dir_ / "oscillator.scene.textproto") << scene;
    const std::string path = (dir_ / "oscillator.study.textproto").string();
    std::ofstream(path) << study;
    return LoadStudyFile(path);
  }
  std::string LoadError(const std::string& study, const std::string& scene = ::mbopt::testing::kOscillatorScene) {
    absl::StatusOr<Study> loaded = Load(study, scene);
    EXPECT_FALSE(loaded.ok());
    return loaded.ok() ? "" : std::string(loaded.status().message());
  }
  std::filesystem::path dir_;
};

// Both rows of `equals: v tolerance: t` are scaled by the size of v, with a
// floor of one of the constraint's unit for v = 0: a band of 1e-5 mm around
// 0 is a limit on the deflection, not a scale of 1e-8 m.
TEST_F(StudyLanguage, EqualityRowsAreScaledByTheValueNotByTheBand) {
  absl::StatusOr<Study> study = Load(std::string(kStudyHead) + kPeakObjective +
                                     "constraints { name: \"zero\" output: \"x\" reduction: REDUCTION_FINAL "
                                     "equals: 0 tolerance: 1e-5 unit: \"mm\" }\n"
                                     "constraints { name: \"two\" output: \"x\" reduction: REDUCTION_MEAN "
                                     "equals: 2 tolerance: 2e-5 unit: \"mm\" }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  absl::StatusOr<StudyLayout> layout = MakeStudyLayout(*study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  ASSERT_EQ(layout->num_constraints(), 4);
  // The rows hold the middle half of the band (+-0.5e-5 mm).
  EXPECT_DOUBLE_EQ(layout->rows[0].limit_si, 0.5e-8);
  EXPECT_DOUBLE_EQ(layout->rows[0].scale, 1e-3);  // one mm
  EXPECT_DOUBLE_EQ(layout->rows[1].scale, 1e-3);
  EXPECT_DOUBLE_EQ(layout->rows[2].scale, 2e-3);  // the value
  EXPECT_DOUBLE_EQ(layout->rows[3].scale, 2e-3);
  EXPECT_DOUBLE_EQ(layout->rows[3].limit_si, -(2.0 - 1e-5) * 1e-3);
}

// Without `tolerance`, `equals: v` holds v to 1e-4 of itself: 60 deg is
// 60 +- 0.006 deg, not a band the user must invent.
TEST_F(StudyLanguage, EqualityWithoutToleranceHoldsATenThousandthOfTheValue) {
  absl::StatusOr<Study> study = Load(std::string(kStudyHead) + kPeakObjective +
                                     "constraints { name: \"end\" output: \"x\" reduction: REDUCTION_FINAL "
                                     "equals: 60 unit: \"mm\" }\n"
                                     "constraints { name: \"zero\" output: \"x\" reduction: REDUCTION_MEAN "
                                     "equals: 0 unit: \"mm\" }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  ASSERT_EQ(study->constraints.size(), 2u);
  EXPECT_DOUBLE_EQ(*study->constraints[0].lower, 60 - 0.006);
  EXPECT_DOUBLE_EQ(*study->constraints[0].upper, 60 + 0.006);
  EXPECT_DOUBLE_EQ(*study->constraints[1].lower, -1e-4);  // a ten-thousandth of one mm
  EXPECT_DOUBLE_EQ(*study->constraints[1].upper, 1e-4);
  EXPECT_THAT(LoadError(std::string(kStudyHead) + kPeakObjective +
                        "constraints { name: \"end\" output: \"x\" reduction: REDUCTION_FINAL equals: 60 "
                        "tolerance: -1 }\n"),
              HasSubstr("constraints[0].tolerance: the half-width of the band"));
}

// No objective: a study that finds a design meeting its constraints, with
// one constant objective term F = 0.
TEST_F(StudyLanguage, StudyWithoutAnObjectiveFindsAFeasibleDesign) {
  absl::StatusOr<Study> study = Load(std::string(kStudyHead) +
                                     "constraints { name: \"travel\" output: \"x\" reduction: REDUCTION_MAX_ABS "
                                     "limit: 5 unit: \"mm\" }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_EQ(study->objective.form, Objective::Form::kFeasible);
  absl::StatusOr<StudyLayout> layout = MakeStudyLayout(*study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  EXPECT_EQ(layout->objective_form, ObjectiveForm::kScalar);
  EXPECT_EQ(layout->num_objective_terms(), 1);
  const std::vector<std::vector<double>> acc = {std::vector<double>(11, 3.0)};
  const std::vector<std::vector<double>> x = {std::vector<double>(11, 1e-3)};
  absl::StatusOr<StudyValues> values = ComputeStudyValues(*study, *layout, {&x, &acc});
  ASSERT_TRUE(values.ok()) << values.status();
  EXPECT_EQ(values->objective, 0.0);
  ASSERT_EQ(values->objective_terms.size(), 1u);
  EXPECT_EQ(values->objective_terms[0], 0.0);
  EXPECT_NEAR(values->max_violation, 1e-3 / 5e-3 - 1, 1e-12);
}

TEST_F(StudyLanguage, StudyWithoutObjectiveOrConstraintsIsRefusedSayingWhatToAdd) {
  EXPECT_THAT(LoadError(kStudyHead), HasSubstr("objective: missing, and the study has no constraints either"));
  // An `objective { }` without a form is a mistake, not a feasibility study.
  EXPECT_THAT(LoadError(std::string(kStudyHead) + "objective { unit: \"N\" }\n" +
                        "constraints { name: \"travel\" output: \"x\" reduction: REDUCTION_MAX_ABS limit: 5 }\n"),
              HasSubstr("objective: empty: expected `minimize_max_of`"));
  EXPECT_THAT(LoadError(std::string(kStudyHead) +
                        "constraints { name: \"travel\" output: \"x\" reduction: REDUCTION_MAX_ABS limit: 5 }\n"
                        "optimizer { objective_target: 1 }\n"),
              HasSubstr("optimizer.objective_target: the study has no objective"));
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test setup: \"" << from << "\" not in the text";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The oscillator whose spring is k_eff = 2 * k_half, written before the
// parameter it reads, k_half = 50 N/m through `half` = 0.5 (a chain), and a
// grid that ends at 2 * duration = 1 s.
std::string DerivedScene() {
  std::string scene = Replace(::mbopt::testing::kOscillatorScene, "parameters { name: \"k\" value: 100 unit: \"N/m\" }",
                              "parameters { name: \"k_eff\" expr: \"2 * k_half\" unit: \"N/m\" }\n"
                              "parameters { name: \"k\" value: 100 unit: \"N/m\" }\n"
                              "parameters { name: \"k_half\" expr: \"half * k\" }\n"
                              "parameters { name: \"half\" value: 0.5 }\n"
                              "parameters { name: \"duration\" value: 500 unit: \"ms\" }");
  scene = Replace(scene, "stiffness_n_per_m { param: \"k\" }", "stiffness_n_per_m { param: \"k_eff\" }");
  return Replace(scene, "time_grid { start_s: 0 end_s: 1 points: 11 }",
                 "time_grid { start_s: 0 end_expr: \"2 * duration\" points: 11 }");
}

// A parameter written as an expression follows the parameters it reads at
// every design point: the field naming it holds its expression, which reads
// only plain parameters (k, through k_half).
TEST_F(StudyLanguage, ParameterWrittenAsAnExpressionFollowsThoseItReads) {
  absl::StatusOr<Study> study = Load(std::string(kStudyHead) + kPeakObjective, DerivedScene());
  ASSERT_TRUE(study.ok()) << study.status();
  const Scene& scene = study->scene;
  const int k_eff = scene.FindParameter("k_eff"), k = scene.FindParameter("k");
  ASSERT_GE(k_eff, 0);
  ASSERT_GE(k, 0);
  EXPECT_DOUBLE_EQ(scene.parameters[static_cast<size_t>(k_eff)].value_si, 100.0);
  const Number& stiffness = std::get<LumpedModel>(scene.model).elements[0].stiffness_n_per_m;
  EXPECT_TRUE(stiffness.DependsOn(k));
  EXPECT_FALSE(stiffness.DependsOn(k_eff));
  // The design sets k (x1 = 12 with scale 10: 120 N/m): the spring is 120 N/m.
  const std::vector<double> values = study->ParameterValuesAt({12.0});
  EXPECT_DOUBLE_EQ(stiffness.Resolve(values), 120.0);
  // The grid's end is 2 * 0.5 s.
  EXPECT_DOUBLE_EQ(scene.time_grid.end_s, 1.0);
}

TEST_F(StudyLanguage, ParametersThatReadEachOtherInACycleAreRefusedNamingTheCycle) {
  const std::string scene = Replace(::mbopt::testing::kOscillatorScene, "parameters { name: \"mass\" value: 2 unit: \"kg\" }",
                                    "parameters { name: \"mass\" value: 2 unit: \"kg\" }\n"
                                    "parameters { name: \"a\" expr: \"b + 1\" }\n"
                                    "parameters { name: \"b\" expr: \"2 * c\" }\n"
                                    "parameters { name: \"c\" expr: \"a - mass\" }");
  const std::string error = LoadError(std::string(kStudyHead) + kPeakObjective, scene);
  EXPECT_THAT(error, HasSubstr("parameters[2].expr: parameters read each other in a cycle: a -> b -> c -> a"));
  // Reported once, where it closes.
  EXPECT_EQ(error.find("in a cycle"), error.rfind("in a cycle")) << error;
}

TEST_F(StudyLanguage, ADesignVariableOrLoadCaseCannotSetAParameterWrittenAsAnExpression) {
  const std::string study = Replace(std::string(kStudyHead) + kPeakObjective, "parameter: \"k\"", "parameter: \"k_eff\"");
  EXPECT_THAT(LoadError(study, DerivedScene()),
              HasSubstr("variables[0].parameter: parameter \"k_eff\" is an expression of other parameters"));
  EXPECT_THAT(LoadError(std::string(kStudyHead) + kPeakObjective +
                            "cases { name: \"soft\" set { parameter: \"k_half\" value: 20 } }\n",
                        DerivedScene()),
              HasSubstr("cases[0].set[0].parameter: parameter \"k_half\" is an expression of other parameters"));
}

// The grid, windows and `equals` values may be expressions of parameters the
// study does not vary; one that reads a varied parameter is refused.
TEST_F(StudyLanguage, GridWindowsAndEqualsValuesAreExpressionsOfFixedParameters) {
  absl::StatusOr<Study> study =
      Load(std::string(kStudyHead) +
               "objective { minimize_max_of: \"acc\" reduction: REDUCTION_MAX_ABS window { from_expr: \"duration / 2\" "
               "} }\n"
               "constraints { name: \"mean\" output: \"x\" reduction: REDUCTION_MEAN equals_expr: \"duration / 250\" "
               "tolerance: 0.01 unit: \"mm\" }\n",
           DerivedScene());
  ASSERT_TRUE(study.ok()) << study.status();
  ASSERT_TRUE(study->objective.window.from_s.has_value());
  EXPECT_DOUBLE_EQ(*study->objective.window.from_s, 0.25);
  ASSERT_EQ(study->constraints.size(), 1u);
  ASSERT_TRUE(study->constraints[0].equals.has_value());
  EXPECT_DOUBLE_EQ(*study->constraints[0].equals, 2.0);  // 2e-3 m in mm
  EXPECT_DOUBLE_EQ(*study->constraints[0].upper, 2.01);

  const std::string varies_duration =
      "variables { name: \"d\" parameter: \"duration\" scale: 1 initial: 500 lower: 400 upper: 600 }\n";
  EXPECT_THAT(LoadError(std::string(kStudyHead) + varies_duration + kPeakObjective, DerivedScene()),
              HasSubstr("scene_file: the scene's time grid is the same at every design point, but it reads "
                        "parameter \"duration\""));
  EXPECT_THAT(LoadError(std::string(kStudyHead) + "variables { name: \"m\" parameter: \"mass\" lower: 1 upper: 3 }\n" +
                            "objective { minimize_max_of: \"acc\" reduction: REDUCTION_MAX_ABS window { from_expr: "
                            "\"mass / 10\" } }\n",
                        DerivedScene()),
              HasSubstr("objective.window.from_expr: a window is the same at every design point, but it reads "
                        "parameter \"mass\""));
}

// A response names a parameter written as an expression like any other.
TEST_F(StudyLanguage, ResponseReadsAParameterWrittenAsAnExpression) {
  absl::StatusOr<Study> study = Load(std::string(kStudyHead) + "responses { name: \"force\" expr: \"k_eff * x\" }\n" +
                                         "objective { minimize_max_of: \"force\" reduction: REDUCTION_MAX_ABS }\n",
                                     DerivedScene());
  ASSERT_TRUE(study.ok()) << study.status();
  ASSERT_EQ(study->responses.size(), 1u);
  const int k = study->scene.FindParameter("k");
  const std::vector<int>& read = study->responses[0].expression->parameters();
  EXPECT_NE(std::find(read.begin(), read.end(), study->ParameterNameIndex(k)), read.end());
  EXPECT_EQ(std::find(read.begin(), read.end(), study->ParameterNameIndex(study->scene.FindParameter("k_eff"))),
            read.end());
}

// Messages written before the multibody model existed say now what does
// what was asked.
TEST_F(StudyLanguage, LinkageWithoutADriverPointsToAMultibodyScene) {
  const std::string path = (dir_ / "linkage.scene.textproto").string();
  std::ofstream(path) << R"pb(name: "free linkage"
linkage {
  joints { name: "O2" ground: true position_m { x { value: 0 } y { value: 0 } } }
  joints { name: "A" position_m { x { value: 0 } y { value: 0.1 } } }
  links { name: "crank" joint_a: "O2" joint_b: "A" }
}
outputs { name: "angle" link_rotation { link: "crank" } }
time_grid { start_s: 0 end_s: 1 points: 2 }
)pb";
  absl::StatusOr<Scene> scene = LoadSceneFile(path);
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(scene.status().message(), HasSubstr("linkage.driver: missing: a linkage is driven at a prescribed speed"));
  EXPECT_THAT(scene.status().message(), HasSubstr("to let the mechanism move freely"));
  EXPECT_THAT(scene.status().message(), HasSubstr("write it as a `multibody` scene"));
}

TEST_F(StudyLanguage, GravityInALumpedScenePointsToAMultibodyScene) {
  const std::string error = LoadError(std::string(kStudyHead) + kPeakObjective,
                                      std::string(::mbopt::testing::kOscillatorScene) +
                                          "effects { gravity { acceleration_m_per_s2 { y { value: -9.81 } } } }\n");
  EXPECT_THAT(error, HasSubstr("effects.gravity: a lumped model moves by small amounts about its static equilibrium"));
  EXPECT_THAT(error, HasSubstr("write it as a `multibody` scene, which takes `effects { gravity { ... } }`"));
}

TEST_F(StudyLanguage, JointTypeOnALinkagePointsToMultibodyJointKinds) {
  const std::string path = (dir_ / "linkage.scene.textproto").string();
  std::ofstream(path) << R"pb(name: "slider"
linkage {
  joints { name: "O2" type: "slider" ground: true }
}
)pb";
  absl::StatusOr<Scene> scene = LoadSceneFile(path);
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(scene.status().message(), HasSubstr(":3:"));
  EXPECT_THAT(scene.status().message(), HasSubstr("Message type \"mbopt.v1.Joint\" has no field named \"type\""));
  EXPECT_THAT(scene.status().message(), HasSubstr("write the mechanism as a `multibody` scene, whose joints take "
                                                  "`kind: JOINT_PRISMATIC`"));
}

TEST_F(StudyLanguage, ReductionEqualPointsToEquals) {
  const std::string error = LoadError(std::string(kStudyHead) + kPeakObjective +
                                      "constraints { name: \"end\" output: \"x\" reduction: REDUCTION_EQUAL limit: 1 }\n");
  EXPECT_THAT(error, HasSubstr("Unknown enumeration value of \"REDUCTION_EQUAL\""));
  EXPECT_THAT(error, HasSubstr("to hold a value, write `equals: <value>`"));
}

// A sum of peaks: each term is a group of the optimizer's terms whose largest
// is its value (MAX_ABS: f and -f at every instant; a whole-series term: one),
// and F adds the groups' largest, weighted.
TEST_F(StudyLanguage, SumOfPeaksLaysOutOneGroupPerTerm) {
  absl::StatusOr<Study> study = Load(std::string(kStudyHead) +
                                     "objective { minimize_sum { terms { output: \"acc\" reduction: REDUCTION_MAX_ABS "
                                     "weight: 2 } terms { output: \"x\" unit: \"mm\" } terms { output: \"x\" "
                                     "reduction: REDUCTION_MIN weight: -3 } } }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  absl::StatusOr<StudyLayout> layout = MakeStudyLayout(*study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  const int instants = static_cast<int>(layout->instants_s.size());
  ASSERT_GT(instants, 2);
  EXPECT_EQ(layout->objective_form, ObjectiveForm::kSumOfMax);
  EXPECT_EQ(layout->objective_group_sizes, (std::vector<int>{2 * instants, 1, instants}));
  EXPECT_EQ(layout->num_objective_terms(), 3 * instants + 1);

  // Values: acc_i = sin(i) - 0.3 and x_i = 0.01 (i - 2)^2 m.
  std::vector<std::vector<std::vector<double>>> series(layout->outputs.size());
  int acc = -1, x = -1;
  for (size_t o = 0; o < layout->outputs.size(); ++o) {
    if (study->SignalName(static_cast<int>(o)) == "acc") acc = static_cast<int>(o);
    if (study->SignalName(static_cast<int>(o)) == "x") x = static_cast<int>(o);
    series[o].assign(static_cast<size_t>(layout->outputs[o].series), std::vector<double>(static_cast<size_t>(instants), 0.0));
  }
  ASSERT_GE(acc, 0);
  ASSERT_GE(x, 0);
  double peak_acc = 0, min_x = 1e300;
  for (int i = 0; i < instants; ++i) {
    series[static_cast<size_t>(acc)][0][static_cast<size_t>(i)] = std::sin(i) - 0.3;
    series[static_cast<size_t>(x)][0][static_cast<size_t>(i)] = 0.01 * (i - 2) * (i - 2);
    peak_acc = std::max(peak_acc, std::abs(std::sin(i) - 0.3));
    min_x = std::min(min_x, 0.01 * (i - 2) * (i - 2));
  }
  std::vector<const std::vector<std::vector<double>>*> outputs;
  for (const auto& s : series) outputs.push_back(&s);
  absl::StatusOr<StudyValues> values = ComputeStudyValues(*study, *layout, outputs);
  ASSERT_TRUE(values.ok()) << values.status();
  const double x_final_mm = 1e3 * 0.01 * (instants - 3) * (instants - 3);
  EXPECT_NEAR(values->objective, 2 * peak_acc + x_final_mm - 3 * min_x, 1e-9);
}

// Only a sum that pushes a peak down has a bound: a peak with a negative
// weight, or a smallest value with a positive one, is refused with what to
// write instead.
TEST_F(StudyLanguage, SumOfPeaksRefusesPeaksItWouldRaise) {
  EXPECT_THAT(LoadError(std::string(kStudyHead) +
                        "objective { minimize_sum { terms { output: \"acc\" reduction: REDUCTION_MAX weight: -1 } "
                        "terms { output: \"x\" } } }\n"),
              HasSubstr("objective.minimize_sum.terms[0].weight: a peak (REDUCTION_MAX) in a sum must weigh more "
                        "than 0, got -1"));
  EXPECT_THAT(LoadError(std::string(kStudyHead) +
                        "objective { minimize_sum { terms { output: \"acc\" reduction: REDUCTION_MIN } } }\n"),
              HasSubstr("objective.minimize_sum.terms[0].weight: REDUCTION_MIN in a sum needs a negative weight"));
}

// Units engineers write, each checked against the field's kind.
TEST_F(StudyLanguage, UnitsEngineersWriteLoadAndAreCheckedAgainstTheField) {
  std::string scene = Replace(::mbopt::testing::kOscillatorScene, "damping_n_s_per_m { value: 0.5 }",
                              "damping_n_s_per_m { param: \"c\" }");
  scene = Replace(scene, "parameters { name: \"mass\" value: 2 unit: \"kg\" }",
                  "parameters { name: \"mass\" value: 2 unit: \"kg\" }\nparameters { name: \"c\" value: 0.0005 unit: "
                  "\"kN s/m\" }");
  absl::StatusOr<Study> study = Load(std::string(kStudyHead) + kPeakObjective, scene);
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_DOUBLE_EQ(study->scene.parameters[static_cast<size_t>(study->scene.FindParameter("c"))].value_si, 0.5);

  EXPECT_THAT(LoadError(std::string(kStudyHead) + kPeakObjective, Replace(scene, "\"kN s/m\"", "\"N m/rad\"")),
              HasSubstr("parameter \"c\" has unit \"N m/rad\" (rotational stiffness (torque/angle)) but this field is "
                        "a damping"));
  for (const auto& [unit, si] : {std::pair{"N m/rad", 1.0}, std::pair{"N m s/rad", 1.0}, std::pair{"J", 1.0},
                                 std::pair{"W", 1.0}, std::pair{"kN s/m", 1e3}}) {
    absl::StatusOr<Unit> found = FindUnit(unit);
    ASSERT_TRUE(found.ok()) << unit;
    EXPECT_EQ(found->si_per_unit, si) << unit;
  }
  EXPECT_FALSE(UnitFits(*FindUnit("J"), Dimension::kTorque));
  EXPECT_FALSE(UnitFits(*FindUnit("N m/rad"), Dimension::kStiffness));
}

// The objective's unit as reported: SI by the output's dimension when none
// is written, nothing for a dimensionless value, and the terms' common unit.
TEST_F(StudyLanguage, ObjectiveUnitIsTheOutputsOrTheTermsCommonUnitNeverABareSI) {
  absl::StatusOr<Study> peak = Load(std::string(kStudyHead) + kPeakObjective);
  ASSERT_TRUE(peak.ok()) << peak.status();
  EXPECT_EQ(ReportedObjectiveUnit(*peak), "m/s^2");
  absl::StatusOr<Study> ratio = Load(std::string(kStudyHead) + "responses { name: \"ratio\" expr: \"x / 0.01\" }\n" +
                                     "objective { minimize_max_of: \"ratio\" reduction: REDUCTION_MAX }\n");
  ASSERT_TRUE(ratio.ok()) << ratio.status();
  EXPECT_EQ(ReportedObjectiveUnit(*ratio), "");
  absl::StatusOr<Study> same = Load(std::string(kStudyHead) +
                                    "objective { minimize_max_over { terms { output: \"x\" unit: \"mm\" } "
                                    "terms { output: \"x\" reduction: REDUCTION_RMS unit: \"mm\" weight: 2 } } }\n");
  ASSERT_TRUE(same.ok()) << same.status();
  EXPECT_EQ(ReportedObjectiveUnit(*same), "mm");
  absl::StatusOr<Study> mixed = Load(std::string(kStudyHead) +
                                     "objective { minimize_sum { terms { output: \"x\" unit: \"mm\" } "
                                     "terms { output: \"acc\" reduction: REDUCTION_RMS } } }\n");
  ASSERT_TRUE(mixed.ok()) << mixed.status();
  EXPECT_EQ(ReportedObjectiveUnit(*mixed), "");
  absl::StatusOr<Study> integral = Load(std::string(kStudyHead) +
                                        "objective { minimize: \"x\" reduction: REDUCTION_INTEGRAL unit: \"mm\" }\n");
  ASSERT_TRUE(integral.ok()) << integral.status();
  EXPECT_EQ(ReportedObjectiveUnit(*integral), "mm s");
}

}  // namespace
}  // namespace mbopt::spec::io
