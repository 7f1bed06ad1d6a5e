// External scenes through the worker's analyzer: the scene's inputs reach
// the driver's parameters, the driver's results become the scene's outputs
// and the study's values, exactly, and every mismatch is a failed analysis
// that names what is wrong. The drivers are /bin/sh scripts.
#include "worker/external/scene_analyzer.h"

#include <filesystem>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "spec/layout.h"
#include "tests/testing/temp_dir.h"
#include "worker/engine/evaluate_study.h"

namespace mbopt::external {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::mbopt::testing::TempDir;

// Design variable "a" sets the driver's parameter "a"; the driver echoes it
// back as the value "f" and in the series "y", and writes "b" too.
const char kStudy[] = R"pb(name: "echo study"
scene {
  name: "echo"
  parameters { name: "a" value: 0.1 }
  parameters { name: "b" value: -3 }
  external {
    driver: "echo"
    inputs { name: "a" value { param: "a" } }
    inputs { name: "b" value { param: "b" } }
  }
  outputs { name: "f" external_value { name: "f" } }
  outputs { name: "y" external_series { name: "y" } }
  time_grid { start_s: 0 end_s: 1 points: 3 }
}
variables { name: "a" parameter: "a" scale: 1 initial: 0.1 lower: -1 upper: 1 }
objective { minimize: "f" }
constraints { name: "y" output: "y" reduction: REDUCTION_MAX limit: 10 }
)pb";

// Prints the input's values back as results (no "time": one number per
// grid instant).
const char kEchoScript[] = R"(. ./input.sh
printf '{"values": {"f": %s, "b": %s}, "series": {"y": [%s, %s, %s]}}' "$a" "$b" "$b" "$a" "$b" > results.json
)";

spec::Study ReadStudy(const std::string& text = kStudy) {
  absl::StatusOr<v1::Study> message = spec::io::ParseStudyText(text, "echo.study.textproto");
  EXPECT_TRUE(message.ok()) << message.status();
  absl::StatusOr<spec::Study> study = spec::io::StudyFromProto(*message, "echo.study.textproto");
  EXPECT_TRUE(study.ok()) << study.status();
  return *std::move(study);
}

DriverDeclaration EchoDriver(const TempDir& base, const std::string& script = kEchoScript) {
  base.Write("run.sh", script, /*executable=*/true);
  DriverDeclaration d;
  d.name = "echo";
  d.command = {"/bin/sh", "./run.sh"};
  d.base_directory = base.path();
  d.files = {"run.sh"};
  d.parameters = {"a", "b"};
  d.input_template_text = "a={a}\nb={b}\n";
  d.input_template_source = "in.tmpl";
  d.input_file = "input.sh";
  d.results_file = "results.json";
  d.timeout_s = 20.0;
  return d;
}

class ExternalSceneAnalysis : public ::testing::Test {
 protected:
  void SetUp() override {
    settings_.drivers = {EchoDriver(base_)};
    settings_.work_directory = work_.path() / "runs";
  }
  TempDir base_, work_;
  ExternalWorkerSettings settings_;
};

TEST_F(ExternalSceneAnalysis, DesignValuesReachTheDriverAndComeBackAsStudyValuesBitForBit) {
  const spec::Study study = ReadStudy();
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  const ExternalSceneAnalyzer analyzer(settings_, "job-1/7/1");
  // 0.7 has no short decimal form: it reaches the driver as %.17g text.
  absl::StatusOr<engine::StudyEvaluation> evaluation =
      engine::EvaluateStudy(study, *layout, {0.7}, /*want_gradients=*/false, &analyzer);
  ASSERT_TRUE(evaluation.ok()) << evaluation.status();
  ASSERT_TRUE(evaluation->ok()) << evaluation->failure.reason;
  EXPECT_EQ(evaluation->values->objective_terms, std::vector<double>{0.7});
  // y = (b, a, b) at the three instants (g_h in SI; the layout's rows hold
  // the limit).
  EXPECT_EQ(evaluation->values->constraint_values, (std::vector<double>{-3.0, 0.7, -3.0}));
  // The folder is gone once the results are read.
  EXPECT_TRUE(std::filesystem::is_empty(settings_.work_directory));
}

TEST_F(ExternalSceneAnalysis, KeptFoldersCarryTheLabelAndNeverRepeat) {
  settings_.keep_run_folders = true;
  const spec::Study study = ReadStudy();
  const ExternalSceneAnalyzer analyzer(settings_, "job-1/7/1");
  for (int i = 0; i < 2; ++i) {
    const spec::AnalysisReport report = analyzer.AnalyzeExternal(study.scene, study.ParameterValuesAt({0.5}));
    ASSERT_TRUE(report.ok()) << report.failure.reason;
  }
  EXPECT_TRUE(std::filesystem::is_directory(settings_.work_directory / "job-1-7-1-1-echo"));
  EXPECT_TRUE(std::filesystem::is_directory(settings_.work_directory / "job-1-7-1-2-echo"));
}

TEST_F(ExternalSceneAnalysis, AnUndeclaredDriverIsTheServicesFailureListingTheDeclaredOnes) {
  settings_.drivers[0].name = "other";
  const spec::Study study = ReadStudy();
  const ExternalSceneAnalyzer analyzer(settings_, "t");
  const spec::AnalysisReport report = analyzer.AnalyzeExternal(study.scene, study.ParameterValuesAt({0.5}));
  EXPECT_EQ(report.failure.kind, spec::FailureKind::kService);
  EXPECT_THAT(report.failure.reason, AllOf(HasSubstr("no driver \"echo\""), HasSubstr("it declares: \"other\"")));
}

TEST_F(ExternalSceneAnalysis, InputsThatDoNotMatchTheDeclarationAreNamed) {
  settings_.drivers[0].parameters = {"a", "c"};
  const spec::Study study = ReadStudy();
  const ExternalSceneAnalyzer analyzer(settings_, "t");
  spec::AnalysisReport report = analyzer.AnalyzeExternal(study.scene, study.ParameterValuesAt({0.5}));
  EXPECT_EQ(report.failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_THAT(report.failure.reason, AllOf(HasSubstr("echo.study.textproto"), HasSubstr("external.inputs[1].name"),
                                           HasSubstr("no parameter \"b\"; it declares: \"a\", \"c\"")));
  settings_.drivers[0].parameters = {"a", "b", "c"};
  report = analyzer.AnalyzeExternal(study.scene, study.ParameterValuesAt({0.5}));
  EXPECT_THAT(report.failure.reason, HasSubstr("takes parameter \"c\" and no input gives it a value"));
}

TEST_F(ExternalSceneAnalysis, ADriversBadExitIsAFailedAnalysisQuotingItsStderr) {
  settings_.drivers = {EchoDriver(base_, "echo 'mesh did not converge' >&2\nexit 3\n")};
  const spec::Study study = ReadStudy();
  const ExternalSceneAnalyzer analyzer(settings_, "t");
  const spec::AnalysisReport report = analyzer.AnalyzeExternal(study.scene, study.ParameterValuesAt({0.5}));
  EXPECT_EQ(report.failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_THAT(report.failure.reason, AllOf(HasSubstr("code 3"), HasSubstr("mesh did not converge")));
}

TEST_F(ExternalSceneAnalysis, ADriverPastItsTimeoutIsATimeLimitFailure) {
  settings_.drivers = {EchoDriver(base_, "sleep 30\n")};
  settings_.drivers[0].timeout_s = 0.3;
  settings_.kill_grace_s = 0.2;
  const spec::Study study = ReadStudy();
  const ExternalSceneAnalyzer analyzer(settings_, "t");
  const spec::AnalysisReport report = analyzer.AnalyzeExternal(study.scene, study.ParameterValuesAt({0.5}));
  EXPECT_EQ(report.failure.kind, spec::FailureKind::kTimeLimit);
}

TEST_F(ExternalSceneAnalysis, AResultTheSceneNamesButTheDriverDidNotWriteNamesTheFile) {
  settings_.drivers = {EchoDriver(base_, R"(printf '{"values": {"g": 1}, "series": {"y": [1, 2, 3]}}' > results.json
)")};
  const spec::Study study = ReadStudy();
  const ExternalSceneAnalyzer analyzer(settings_, "t");
  const spec::AnalysisReport report = analyzer.AnalyzeExternal(study.scene, study.ParameterValuesAt({0.5}));
  EXPECT_EQ(report.failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_THAT(report.failure.reason,
              AllOf(HasSubstr("results.json: no value \"f\" (output \"f\")"), HasSubstr("the file's values: \"g\"")));
}

TEST(ExternalOutputs, ASeriesWithItsOwnTimeIsInterpolatedOntoTheGrid) {
  const spec::Study study = ReadStudy();
  ExternalResults results;
  results.values["f"] = 2.0;
  results.time_s = {0.0, 0.25, 1.0};
  results.series["y"] = {0.0, 1.0, 4.0};
  absl::StatusOr<std::vector<spec::OutputValues>> outputs = OutputsFromResults(study.scene, results, "r.json");
  ASSERT_TRUE(outputs.ok()) << outputs.status();
  ASSERT_EQ(outputs->size(), 2u);
  EXPECT_EQ((*outputs)[0].series, std::vector<std::vector<double>>{{2.0}});
  // Grid 0, 0.5, 1: 0.5 lies a third of the way from 0.25 to 1.
  ASSERT_EQ((*outputs)[1].series.size(), 1u);
  EXPECT_EQ((*outputs)[1].series[0][0], 0.0);
  EXPECT_DOUBLE_EQ((*outputs)[1].series[0][1], 2.0);
  EXPECT_EQ((*outputs)[1].series[0][2], 4.0);
}

TEST(ExternalOutputs, AGridBeyondTheDriversTimeOrASeriesOfTheWrongLengthIsRefused) {
  const spec::Study study = ReadStudy();
  ExternalResults results;
  results.values["f"] = 2.0;
  results.time_s = {0.0, 0.5};
  results.series["y"] = {0.0, 1.0};
  absl::StatusOr<std::vector<spec::OutputValues>> outputs = OutputsFromResults(study.scene, results, "r.json");
  ASSERT_FALSE(outputs.ok());
  EXPECT_THAT(outputs.status().message(),
              AllOf(HasSubstr("r.json: series \"y\""), HasSubstr("runs from 0 s to 0.5 s"), HasSubstr("needs 1 s")));
  results.time_s.clear();
  outputs = OutputsFromResults(study.scene, results, "r.json");
  ASSERT_FALSE(outputs.ok());
  EXPECT_THAT(outputs.status().message(), HasSubstr("has 2 numbers and the results give no \"time\""));
}

TEST(ExternalOutputs, WithoutAnAnalyzerAnExternalSceneFailsSayingWhy) {
  const spec::Study study = ReadStudy();
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok());
  absl::StatusOr<engine::StudyEvaluation> evaluation = engine::EvaluateStudy(study, *layout, {0.5}, false);
  ASSERT_TRUE(evaluation.ok());
  EXPECT_EQ(evaluation->failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_THAT(evaluation->failure.reason, HasSubstr("runs no analysis drivers"));
}

}  // namespace
}  // namespace mbopt::external
