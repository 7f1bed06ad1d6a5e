// The study's `sweep` and `sample` sections as a user writes them: what they
// become, and the messages that name the file, line and field of a mistake.
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/design_set.h"
#include "spec/io/design_set_convert.h"
#include "spec/io/study_io.h"
#include "tests/spec/oscillator_scene.h"

namespace mbopt::spec::io {
namespace {

using ::testing::HasSubstr;

// x1 starts at the parameter's value over the scale (k = 100 N/m: 10).
const char kStudyHead[] = R"pb(name: "oscillator sweep"
scene_file: "oscillator.scene.textproto"
variables { name: "x1" parameter: "k" scale: 10 lower: 5 upper: 20 }
objective { minimize_max_of: "acc" reduction: REDUCTION_MAX_ABS }
)pb";

class DesignSetLanguage : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    dir_ = std::filesystem::path(::testing::TempDir()) / ("design_set_language_" + test);
    std::filesystem::create_directories(dir_);
  }
  absl::StatusOr<Study> Load(const std::string& tail) {
    std::ofstream(dir_ / "oscillator.scene.textproto") << ::mbopt::testing::kOscillatorScene;
    path_ = (dir_ / "oscillator.study.textproto").string();
    std::ofstream(path_) << kStudyHead << tail;
    return LoadStudyFile(path_);
  }
  std::string LoadError(const std::string& tail) {
    absl::StatusOr<Study> loaded = Load(tail);
    EXPECT_FALSE(loaded.ok());
    return loaded.ok() ? "" : std::string(loaded.status().message());
  }
  std::filesystem::path dir_;
  std::string path_;
};

TEST_F(DesignSetLanguage, StudyWithoutSweepIsAnOptimization) {
  absl::StatusOr<Study> study = Load("");
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_TRUE(study->design_set.empty());
  EXPECT_EQ(DescribeStudyForm(*study), "an optimization");
}

TEST_F(DesignSetLanguage, LineFromTo) {
  absl::StatusOr<Study> study = Load("sweep { axis { variable: \"x1\" from: 6 to: 14 points: 9 } }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  ASSERT_EQ(study->design_set.form, DesignSet::Form::kSweep);
  ASSERT_EQ(study->design_set.axes.size(), 1u);
  EXPECT_EQ(study->design_set.axes[0].variable, 0);
  EXPECT_EQ(study->design_set.size(), 9);
  const std::vector<std::vector<double>> points = DesignSetPoints(*study);
  ASSERT_EQ(points.size(), 9u);
  EXPECT_EQ(points[0][0], 6.0);
  EXPECT_EQ(points[4][0], 10.0);
  EXPECT_EQ(points[8][0], 14.0);
  EXPECT_EQ(DescribeStudyForm(*study), "a sweep of x1 (9 points from 6 to 14, scaled)");
}

TEST_F(DesignSetLanguage, RelativePercentIsAroundTheInitialDesign) {
  absl::StatusOr<Study> study = Load("sweep { axis { variable: \"x1\" relative_percent: 20 points: 5 } }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_DOUBLE_EQ(study->design_set.axes[0].from, 8.0);
  EXPECT_DOUBLE_EQ(study->design_set.axes[0].to, 12.0);
}

TEST_F(DesignSetLanguage, LatinHypercubeSample) {
  absl::StatusOr<Study> study = Load("sample { latin_hypercube { count: 12 seed: 99 } }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_EQ(study->design_set.form, DesignSet::Form::kLatinHypercube);
  EXPECT_EQ(study->design_set.latin_hypercube.count, 12);
  EXPECT_EQ(study->design_set.latin_hypercube.seed, 99u);
  EXPECT_EQ(DescribeStudyForm(*study), "a Latin hypercube sample of 12 designs (seed 99)");
}

TEST_F(DesignSetLanguage, UnknownVariableNamesTheLineAndTheVariables) {
  const std::string error = LoadError("sweep {\n  axis { variable: \"x9\" from: 6 to: 14 points: 9 }\n}\n");
  EXPECT_THAT(error, HasSubstr("oscillator.study.textproto:6:"));
  EXPECT_THAT(error, HasSubstr("sweep.axis[0].variable"));
  EXPECT_THAT(error, HasSubstr("unknown design variable \"x9\"; the study's variables: \"x1\""));
}

TEST_F(DesignSetLanguage, AxisOutsideTheBoundsIsRefused) {
  const std::string error = LoadError("sweep { axis { variable: \"x1\" from: 4 to: 14 points: 3 } }\n");
  EXPECT_THAT(error, HasSubstr("sweep.axis[0].from"));
  EXPECT_THAT(error, HasSubstr("outside the bounds [5, 20]"));
  EXPECT_THAT(LoadError("sweep { axis { variable: \"x1\" relative_percent: 60 points: 3 } }\n"),
              HasSubstr("sweep.axis[0].relative_percent"));
}

TEST_F(DesignSetLanguage, AxisNeedsARangeAndPoints) {
  EXPECT_THAT(LoadError("sweep { axis { variable: \"x1\" from: 6 points: 3 } }\n"),
              HasSubstr("sweep.axis[0].to: an axis needs from and to"));
  EXPECT_THAT(LoadError("sweep { axis { variable: \"x1\" from: 6 to: 8 } }\n"),
              HasSubstr("sweep.axis[0].points: must be between 1 and"));
  EXPECT_THAT(LoadError("sweep { axis { variable: \"x1\" from: 6 to: 6 points: 4 } }\n"),
              HasSubstr("need a range"));
  EXPECT_THAT(LoadError("sweep { axis { variable: \"x1\" from: 6 to: 8 relative_percent: 5 points: 4 } }\n"),
              HasSubstr("not both"));
  EXPECT_THAT(LoadError("sweep { }\n"), HasSubstr("one axis (a line) or two (a grid), got 0"));
  EXPECT_THAT(LoadError("sweep { axis { variable: \"x1\" from: 6 to: 8 points: 2 } "
                        "axis { variable: \"x1\" from: 6 to: 8 points: 2 } }\n"),
              HasSubstr("swept twice"));
}

TEST_F(DesignSetLanguage, SampleNeedsItsFormAndACount) {
  EXPECT_THAT(LoadError("sample { }\n"), HasSubstr("sample.latin_hypercube: a sample names its form"));
  EXPECT_THAT(LoadError("sample { latin_hypercube { seed: 3 } }\n"),
              HasSubstr("sample.latin_hypercube.count: must be between 1 and"));
  EXPECT_THAT(LoadError("sweep { axis { variable: \"x1\" from: 6 to: 8 points: 2 } }\n"
                        "sample { latin_hypercube { count: 3 } }\n"),
              HasSubstr("a sweep or a sample, not both"));
}

// 100,000 designs of 101 variables would hold 10.1 million values.
TEST_F(DesignSetLanguage, TooManyValuesAreRefused) {
  std::string scene = ::mbopt::testing::kOscillatorScene;
  std::string study = "name: \"wide\"\nscene_file: \"oscillator.scene.textproto\"\n"
                      "objective { minimize_max_of: \"acc\" reduction: REDUCTION_MAX_ABS }\n";
  for (int i = 0; i < 101; ++i) {
    scene += "parameters { name: \"p" + std::to_string(i) + "\" value: 1 }\n";
    study += "variables { name: \"v" + std::to_string(i) + "\" parameter: \"p" + std::to_string(i) +
             "\" lower: 0 upper: 2 }\n";
  }
  std::ofstream(dir_ / "oscillator.scene.textproto") << scene;
  const std::string path = (dir_ / "wide.study.textproto").string();
  std::ofstream(path) << study << "sample { latin_hypercube { count: 99000 } }\n";
  EXPECT_TRUE(LoadStudyFile(path).ok()) << "99,000 x 101 values are within the limit";
  std::ofstream(path) << study << "sample { latin_hypercube { count: 100000 } }\n";
  absl::StatusOr<Study> loaded = LoadStudyFile(path);
  ASSERT_FALSE(loaded.ok());
  EXPECT_THAT(loaded.status().message(),
              HasSubstr("sample: 100000 designs of 101 variables are 10100000 values, more than the limit of 10000000"));
}

}  // namespace
}  // namespace mbopt::spec::io
