// The study's `pareto` section as a user writes it: what it becomes, how
// `mbopt validate` names it, and the messages that name the file, line and
// field of a mistake.
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/io/design_set_convert.h"
#include "spec/io/study_io.h"
#include "tests/spec/oscillator_scene.h"

namespace mbopt::spec::io {
namespace {

using ::testing::HasSubstr;

const char kStudyHead[] = R"pb(name: "oscillator front"
scene_file: "oscillator.scene.textproto"
variables { name: "x1" parameter: "k" scale: 10 lower: 5 upper: 20 }
objective { minimize_max_of: "acc" reduction: REDUCTION_MAX_ABS }
constraints { name: "travel" output: "x" reduction: REDUCTION_MAX_ABS limit: 0.02 unit: "m" }
constraints { name: "low" output: "x" reduction: REDUCTION_MIN limit: -1 unit: "m" }
constraints { name: "settles" output: "x" reduction: REDUCTION_FINAL equals: 0 tolerance: 0.001 }
)pb";

class ParetoLanguage : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    dir_ = std::filesystem::path(::testing::TempDir()) / ("pareto_language_" + test);
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
  std::filesystem::path dir_;
};

TEST_F(ParetoLanguage, AgainstAConstraintWithTheDefaultPoints) {
  absl::StatusOr<Study> study = Load("pareto { against: \"travel\" }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_TRUE(study->pareto.enabled());
  EXPECT_EQ(study->pareto.constraint, 0);
  EXPECT_EQ(study->pareto.points, 9);
  EXPECT_EQ(DescribeStudyForm(*study),
            "a Pareto front of the objective against the largest value of travel (m), 9 points (epsilon-constraint "
            "method)");
}

TEST_F(ParetoLanguage, WithoutTheSectionNoFront) {
  absl::StatusOr<Study> study = Load("");
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_FALSE(study->pareto.enabled());
  EXPECT_EQ(DescribeStudyForm(*study), "an optimization");
}

TEST_F(ParetoLanguage, UnknownConstraintNamesTheLineFieldAndTheConstraints) {
  const std::string error = LoadError("pareto {\n  against: \"stroke\"\n}\n");
  EXPECT_THAT(error, HasSubstr("oscillator.study.textproto:9:"));
  EXPECT_THAT(error, HasSubstr("pareto.against"));
  EXPECT_THAT(error, HasSubstr("unknown constraint \"stroke\"; the study's constraints: \"travel\", \"low\", "
                               "\"settles\""));
  EXPECT_THAT(LoadError("pareto { points: 5 }\n"), HasSubstr("pareto.against: name the constraint"));
}

TEST_F(ParetoLanguage, OnlyAnUpperLimitCanBeTraded) {
  EXPECT_THAT(LoadError("pareto { against: \"low\" }\n"), HasSubstr("is a lower limit (REDUCTION_MIN)"));
  EXPECT_THAT(LoadError("pareto { against: \"settles\" }\n"), HasSubstr("it holds a value (equals)"));
}

TEST_F(ParetoLanguage, PointsOutOfRangeAndSweepsAreRefused) {
  EXPECT_THAT(LoadError("pareto { against: \"travel\" points: 2 }\n"),
              HasSubstr("pareto.points: must be between 3 and 65 (the two ends included), got 2"));
  EXPECT_THAT(LoadError("pareto { against: \"travel\" points: 66 }\n"), HasSubstr("got 66"));
  EXPECT_THAT(LoadError("pareto { against: \"travel\" }\n"
                        "sweep { axis { variable: \"x1\" from: 6 to: 8 points: 2 } }\n"),
              HasSubstr("a Pareto front or a sweep or sample, not both"));
}

TEST_F(ParetoLanguage, RefineAddsPointsUpToOnePerSegment) {
  absl::StatusOr<Study> study = Load("pareto { against: \"travel\" points: 5 refine: 4 }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_EQ(study->pareto.refine, 4);
  EXPECT_EQ(study->pareto.total_points(), 9);
  EXPECT_EQ(DescribeStudyForm(*study),
            "a Pareto front of the objective against the largest value of travel (m), 5 points and 4 more where it "
            "bends (epsilon-constraint method)");
  const std::string error = LoadError("pareto {\n  against: \"travel\"\n  points: 5\n  refine: 5\n}\n");
  EXPECT_THAT(error, HasSubstr("oscillator.study.textproto:11:"));
  EXPECT_THAT(error, HasSubstr("pareto.refine: must be between 0 and 4 (one point in each segment of the 5 points' "
                               "front at most), got 5"));
  EXPECT_THAT(LoadError("pareto { against: \"travel\" refine: -1 }\n"), HasSubstr("got -1"));
}

TEST_F(ParetoLanguage, RefineAgainAddsASecondGenerationUpToOnePerSegmentOfTheRefinedFront) {
  absl::StatusOr<Study> study = Load("pareto { against: \"travel\" points: 5 refine: 2 refine_again: 3 }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_EQ(study->pareto.refine_again, 3);
  EXPECT_EQ(study->pareto.total_points(), 10);
  EXPECT_EQ(DescribeStudyForm(*study),
            "a Pareto front of the objective against the largest value of travel (m), 5 points and 2 more where it "
            "bends, then 3 more where the refined front bends (epsilon-constraint method)");
  const std::string without = LoadError("pareto {\n  against: \"travel\"\n  refine_again: 2\n}\n");
  EXPECT_THAT(without, HasSubstr("oscillator.study.textproto:10:"));
  EXPECT_THAT(without, HasSubstr("pareto.refine_again: refines the refined front again: set `refine`"));
  EXPECT_THAT(LoadError("pareto { against: \"travel\" points: 5 refine: 2 refine_again: 7 }\n"),
              HasSubstr("pareto.refine_again: must be between 0 and 6 (one point in each segment of the refined "
                        "front of 7 points at most), got 7"));
}

// A front of three objectives names two constraints.
const char kReach[] = "constraints { name: \"reach\" output: \"x\" reduction: REDUCTION_MAX limit: 0.05 unit: \"m\" }\n";

TEST_F(ParetoLanguage, TwoConstraintsMakeAFrontOfThreeObjectivesOverAGrid) {
  absl::StatusOr<Study> study = Load(std::string(kReach) + "pareto { against: \"travel\" against: \"reach\" }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_TRUE(study->pareto.three_objectives());
  EXPECT_EQ(study->pareto.constraint, 0);
  EXPECT_EQ(study->pareto.third_constraint, 3);
  EXPECT_EQ(study->pareto.points, 5);
  EXPECT_EQ(study->pareto.total_points(), 28);
  EXPECT_EQ(DescribeStudyForm(*study),
            "a Pareto front of three objectives: the objective, the largest value of travel (m) and the largest "
            "value of reach (m); 3 anchors and a grid of 5 x 5 levels (epsilon-constraint method)");
  absl::StatusOr<Study> three = Load(std::string(kReach) + "pareto { against: \"reach\" against: \"travel\" points: 3 }\n");
  ASSERT_TRUE(three.ok()) << three.status();
  EXPECT_EQ(three->pareto.constraint, 3);
  EXPECT_EQ(three->pareto.total_points(), 12);
}

TEST_F(ParetoLanguage, AFrontOfThreeObjectivesRefusesBadCombinationsNamingLineAndField) {
  const std::string twice = LoadError("pareto {\n  against: \"travel\"\n  against: \"travel\"\n}\n");
  EXPECT_THAT(twice, HasSubstr("oscillator.study.textproto:"));
  EXPECT_THAT(twice, HasSubstr("pareto.against"));
  EXPECT_THAT(twice, HasSubstr("constraint \"travel\" is named twice"));
  EXPECT_THAT(LoadError(std::string(kReach) + "pareto { against: \"travel\" against: \"low\" }\n"),
              HasSubstr("constraint \"low\" cannot be traded: it is a lower limit"));
  EXPECT_THAT(LoadError(std::string(kReach) + "pareto { against: \"travel\" against: \"reach\" against: \"low\" }\n"),
              HasSubstr("pareto.against: a front has two or three objectives: name one or two constraints, got 3"));
  const std::string points = LoadError(std::string(kReach) + "pareto {\n  against: \"travel\"\n  against: \"reach\"\n  points: 12\n}\n");
  EXPECT_THAT(points, HasSubstr("pareto.points: a front of three objectives has `points` levels of each bounded "
                                "objective, from 2 to 9, got 12"));
  EXPECT_THAT(points, HasSubstr(":12:"));  // the line of `points`
  EXPECT_THAT(LoadError(std::string(kReach) + "pareto { against: \"travel\" against: \"reach\" refine: 2 }\n"),
              HasSubstr("pareto.refine: a front of three objectives is not refined"));
  EXPECT_THAT(LoadError(std::string(kReach) +
                        "pareto { against: \"travel\" against: \"reach\" objective { minimize: \"x\" } }\n"),
              HasSubstr("a front of three objectives trades two constraints (`against` twice), not an `objective`"));
}

}  // namespace
}  // namespace mbopt::spec::io
