// A Pareto front's second objective written as an objective
// (`pareto { objective { ... } }`): what each form becomes in the study's
// layout (rows after the constraints', with the factors that make them the
// second objective), and the messages that name the file, line and field
// of a form or combination a front cannot take.
#include <algorithm>
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/io/design_set_convert.h"
#include "spec/io/study_io.h"
#include "spec/layout.h"
#include "tests/spec/oscillator_scene.h"

namespace mbopt::spec::io {
namespace {

using ::testing::HasSubstr;

const char kStudyHead[] = R"pb(name: "oscillator front"
scene_file: "oscillator.scene.textproto"
variables { name: "x1" parameter: "k" scale: 10 lower: 5 upper: 20 }
objective { minimize_max_of: "acc" reduction: REDUCTION_MAX_ABS }
constraints { name: "travel" output: "x" reduction: REDUCTION_MAX_ABS limit: 0.02 unit: "m" }
)pb";

class ParetoSecondObjective : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    dir_ = std::filesystem::path(::testing::TempDir()) / ("pareto_second_objective_" + test);
    std::filesystem::create_directories(dir_);
  }
  absl::StatusOr<Study> Load(const std::string& tail) {
    std::ofstream(dir_ / "oscillator.scene.textproto") << ::mbopt::testing::kOscillatorScene;
    const std::string path = (dir_ / "oscillator.study.textproto").string();
    std::ofstream(path) << kStudyHead << tail;
    return LoadStudyFile(path);
  }
  std::string LoadError(const std::string& tail) {
    absl::StatusOr<Study> loaded = Load(tail);
    EXPECT_FALSE(loaded.ok());
    return loaded.ok() ? "" : std::string(loaded.status().message());
  }
  // The study's layout, checked to keep the constraint's rows of the same
  // study without a front, then the second objective's rows.
  StudyLayout LayoutOf(const Study& study) {
    absl::StatusOr<StudyLayout> layout = MakeStudyLayout(study);
    EXPECT_TRUE(layout.ok()) << layout.status();
    Study without = study;
    without.pareto = Pareto{};
    absl::StatusOr<StudyLayout> plain = MakeStudyLayout(without);
    EXPECT_TRUE(plain.ok()) << plain.status();
    if (!layout.ok() || !plain.ok()) return {};
    const std::size_t constraint_rows = plain->rows.size();
    EXPECT_EQ(layout->rows.size(), constraint_rows + layout->second_objective_factors.size());
    for (std::size_t h = 0; h < layout->rows.size(); ++h) {
      EXPECT_EQ(layout->rows[h].constraint == kSecondObjectiveRow, h >= constraint_rows) << "row " << h;
    }
    return *std::move(layout);
  }
  std::filesystem::path dir_;
};

TEST_F(ParetoSecondObjective, AReducedOutputIsOneRowInTheObjectivesUnit) {
  absl::StatusOr<Study> study =
      Load("pareto { objective { minimize: \"x\" reduction: REDUCTION_RMS unit: \"mm\" } points: 5 }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_TRUE(study->pareto.enabled());
  EXPECT_TRUE(study->pareto.trades_objective);
  EXPECT_EQ(study->pareto.constraint, -1);
  EXPECT_EQ(study->second_objective.form, Objective::Form::kMinimize);
  EXPECT_EQ(DescribeStudyForm(*study),
            "a Pareto front of the objective against a second objective (mm), 5 points (epsilon-constraint method)");
  const StudyLayout layout = LayoutOf(*study);
  ASSERT_EQ(layout.second_objective_factors.size(), 1u);
  EXPECT_FALSE(layout.second_objective_sums);
  EXPECT_DOUBLE_EQ(layout.second_objective_factors[0], 1000.0);  // SI (m) to mm
  EXPECT_EQ(layout.rows.back().value.over, Over::kRms);
  EXPECT_EQ(layout.rows.back().value.sign, 1.0);
}

TEST_F(ParetoSecondObjective, AMaximizedValueIsARowOfItsNegative) {
  absl::StatusOr<Study> study = Load("pareto { objective { maximize: \"x\" } }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  const StudyLayout layout = LayoutOf(*study);
  ASSERT_EQ(layout.second_objective_factors.size(), 1u);
  EXPECT_EQ(layout.second_objective_factors[0], 1.0);
  EXPECT_EQ(layout.rows.back().value.sign, -1.0);
}

TEST_F(ParetoSecondObjective, APeakIsARowPerInstantAsTheObjectivesTerms) {
  absl::StatusOr<Study> study =
      Load("pareto { objective { minimize_max_of: \"acc\" reduction: REDUCTION_MAX_ABS } }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  const StudyLayout layout = LayoutOf(*study);
  // The same peak as the study's own objective: a row for each of its terms.
  ASSERT_EQ(layout.second_objective_factors.size(), layout.objective_terms.size());
  const std::size_t first = layout.rows.size() - layout.second_objective_factors.size();
  for (std::size_t j = 0; j < layout.objective_terms.size(); ++j) {
    EXPECT_EQ(layout.rows[first + j].value.instant, layout.objective_terms[j].instant);
    EXPECT_EQ(layout.rows[first + j].value.sign, layout.objective_terms[j].sign);
    EXPECT_EQ(layout.second_objective_factors[j], 1.0);
  }
}

TEST_F(ParetoSecondObjective, ALargestOfTermsKeepsTheirWeights) {
  absl::StatusOr<Study> study = Load(R"pb(pareto { objective { minimize_max_over {
  terms { output: "x" reduction: REDUCTION_RMS weight: 2 }
  terms { output: "x" reduction: REDUCTION_FINAL weight: 0.5 unit: "mm" }
} } }
)pb");
  ASSERT_TRUE(study.ok()) << study.status();
  const StudyLayout layout = LayoutOf(*study);
  ASSERT_EQ(layout.second_objective_factors.size(), 2u);
  EXPECT_FALSE(layout.second_objective_sums);
  EXPECT_DOUBLE_EQ(layout.second_objective_factors[0], 2.0);
  EXPECT_DOUBLE_EQ(layout.second_objective_factors[1], 500.0);
}

TEST_F(ParetoSecondObjective, ASumOfOneValueTermsIsSummedWithItsWeights) {
  absl::StatusOr<Study> study = Load(R"pb(pareto { objective { minimize_sum {
  terms { output: "x" reduction: REDUCTION_RMS weight: 2 }
  terms { output: "x" reduction: REDUCTION_FINAL weight: -3 }
} } }
)pb");
  ASSERT_TRUE(study.ok()) << study.status();
  const StudyLayout layout = LayoutOf(*study);
  ASSERT_EQ(layout.second_objective_factors.size(), 2u);
  EXPECT_TRUE(layout.second_objective_sums);
  // A sum is one row of its own at a point: its weights keep their signs.
  EXPECT_EQ(layout.second_objective_factors[0], 2.0);
  EXPECT_EQ(layout.second_objective_factors[1], -3.0);
  EXPECT_EQ(layout.rows.back().value.sign, 1.0);
}

TEST_F(ParetoSecondObjective, FormsAndCombinationsAFrontCannotTakeAreRefused) {
  EXPECT_THAT(LoadError("pareto { against: \"travel\" objective { minimize: \"x\" } }\n"),
              HasSubstr("pareto.against: a front has one second objective: a constraint's largest value "
                        "(`against: \"travel\"`) or an `objective`, not both"));
  EXPECT_THAT(LoadError("pareto { objective { target_distance { terms { output: \"x\" target: 0 } } } }\n"),
              HasSubstr("pareto.objective: target_distance cannot be a second objective"));
  EXPECT_THAT(LoadError(R"pb(pareto { objective { minimize_sum {
  terms { output: "x" }
  terms { output: "acc" reduction: REDUCTION_MAX }
} } }
)pb"),
              HasSubstr("pareto.objective: minimize_sum.terms[1] is a peak"));
  EXPECT_THAT(LoadError("pareto { objective { } }\n"),
              HasSubstr("pareto.objective: empty: expected `minimize`, `maximize`, `minimize_max_of`"));
}

TEST_F(ParetoSecondObjective, AMistakeInsideItNamesItsLineAndField) {
  const std::string error = LoadError("pareto {\n  objective {\n    minimize: \"stroke\"\n  }\n}\n");
  EXPECT_THAT(error, HasSubstr("oscillator.study.textproto:8:"));
  EXPECT_THAT(error, HasSubstr("pareto.objective.minimize"));
  EXPECT_THAT(error, HasSubstr("stroke"));
  EXPECT_THAT(LoadError("pareto { objective { minimize: \"x\" unit: \"N\" } }\n"),
              HasSubstr("pareto.objective.unit"));
  // What only the layout sees is named as the front's field too.
  EXPECT_THAT(LoadError("pareto { objective { minimize_max_of: \"x\" reduction: REDUCTION_MAX "
                        "window { from_s: 5 to_s: 6 } } }\n"),
              HasSubstr("oscillator.study.textproto: pareto.objective"));
}

}  // namespace
}  // namespace mbopt::spec::io
