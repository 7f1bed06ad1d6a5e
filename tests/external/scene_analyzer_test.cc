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

// Gradients the driver writes (docs/external.md, "Gradients"). The driver
// computes f = a b and y = (a, b, a b) with their derivatives in its own
// parameters a and b; the scene gives it a = p and b = c p through an
// expression, and the design variable x sets p = 2 x. So at x the study
// sees f = c (2x)^2 with df/dx = 8 c x, and y's rows (2x, 2cx, 4cx^2) with
// derivatives (2, 2c, 8cx): the chain rule through the expression and the
// variable's scale.
const char kProductStudy[] = R"pb(name: "product study"
scene {
  name: "product"
  parameters { name: "p" value: 0.1 }
  parameters { name: "c" value: -3 }
  external {
    driver: "product"
    inputs { name: "a" value { param: "p" } }
    inputs { name: "b" value { expr: "c * p" } }
  }
  outputs { name: "f" external_value { name: "f" } }
  outputs { name: "y" external_series { name: "y" } }
  time_grid { start_s: 0 end_s: 1 points: 3 }
}
variables { name: "x" parameter: "p" scale: 2 initial: 0.1 lower: -1 upper: 1 }
objective { minimize: "f" }
constraints { name: "y" output: "y" reduction: REDUCTION_MAX limit: 10 }
optimizer { sensitivity: SENSITIVITY_METHOD_SIMULATOR }
)pb";

const char kProductJsonScript[] = R"(. ./input.sh
awk -v a="$a" -v b="$b" 'BEGIN {
  printf "{\"values\": {\"f\": %.17g}, \"series\": {\"y\": [%.17g, %.17g, %.17g]},\n", a * b, a, b, a * b
  printf " \"gradients\": {\"values\": {\"f\": {\"a\": %.17g, \"b\": %.17g}},\n", b, a
  printf "   \"series\": {\"y\": {\"a\": [1, 0, %.17g], \"b\": [0, 1, %.17g]}}}}\n", b, a
}' > results.json
)";

// The same model without the series, in Dakota's format: f = a b and
// g = a + b, then their gradients in the order the driver declares a, b.
const char kProductDakotaScript[] = R"(. ./input.sh
awk -v a="$a" -v b="$b" 'BEGIN {
  printf "%.17g f\n%.17g g\n[ %.17g %.17g ]\n[ 1 1 ]\n", a * b, a + b, b, a
}' > results.out
)";

DriverDeclaration ProductDriver(const TempDir& base, const std::string& script, ResultsFormat format) {
  DriverDeclaration d = EchoDriver(base, script);
  d.name = "product";
  d.results_format = format;
  d.results_file = format == ResultsFormat::kJson ? "results.json" : "results.out";
  return d;
}

TEST_F(ExternalSceneAnalysis, TheDriversGradientsAreTheStudysGradientsThroughTheChainRule) {
  settings_.drivers = {ProductDriver(base_, kProductJsonScript, ResultsFormat::kJson)};
  const spec::Study study = ReadStudy(kProductStudy);
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  const ExternalSceneAnalyzer analyzer(settings_, "t");
  const double x = 0.7, c = -3.0;
  absl::StatusOr<engine::StudyEvaluation> evaluation =
      engine::EvaluateStudy(study, *layout, {x}, /*want_gradients=*/true, &analyzer);
  ASSERT_TRUE(evaluation.ok()) << evaluation.status();
  ASSERT_TRUE(evaluation->ok()) << evaluation->failure.reason;
  ASSERT_TRUE(evaluation->gradients.has_value()) << evaluation->gradients_unavailable;
  ASSERT_EQ(evaluation->values->objective_terms.size(), 1u);
  EXPECT_DOUBLE_EQ(evaluation->values->objective_terms[0], c * (2 * x) * (2 * x));
  ASSERT_EQ(evaluation->gradients->objective_terms.size(), 1u);
  ASSERT_EQ(evaluation->gradients->objective_terms[0].size(), 1u);
  EXPECT_DOUBLE_EQ(evaluation->gradients->objective_terms[0][0], 8 * c * x);
  const std::vector<double> expected_rows = {2.0, 2 * c, 8 * c * x};
  ASSERT_EQ(evaluation->gradients->constraint_rows.size(), expected_rows.size());
  for (size_t r = 0; r < expected_rows.size(); ++r) {
    EXPECT_DOUBLE_EQ(evaluation->gradients->constraint_rows[r][0], expected_rows[r]) << "row " << r;
  }
}

TEST_F(ExternalSceneAnalysis, DakotaGradientLinesGiveTheSameGradientsBitForBit) {
  std::string dakota_study = kProductStudy;
  dakota_study.replace(dakota_study.find(R"(outputs { name: "y" external_series { name: "y" } })"),
                       std::string(R"(outputs { name: "y" external_series { name: "y" } })").size(),
                       R"(outputs { name: "g" external_value { name: "g" } })");
  dakota_study.replace(dakota_study.find(R"(output: "y" reduction: REDUCTION_MAX)"),
                       std::string(R"(output: "y" reduction: REDUCTION_MAX)").size(),
                       R"(output: "g" reduction: REDUCTION_FINAL)");
  settings_.drivers = {ProductDriver(base_, kProductDakotaScript, ResultsFormat::kDakota)};
  const spec::Study study = ReadStudy(dakota_study);
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  const ExternalSceneAnalyzer analyzer(settings_, "t");
  const double x = 0.7, c = -3.0;
  absl::StatusOr<engine::StudyEvaluation> evaluation =
      engine::EvaluateStudy(study, *layout, {x}, /*want_gradients=*/true, &analyzer);
  ASSERT_TRUE(evaluation.ok()) << evaluation.status();
  ASSERT_TRUE(evaluation->ok()) << evaluation->failure.reason;
  ASSERT_TRUE(evaluation->gradients.has_value()) << evaluation->gradients_unavailable;
  EXPECT_DOUBLE_EQ(evaluation->gradients->objective_terms[0][0], 8 * c * x);
  // g = p + c p: dg/dx = 2 (1 + c).
  ASSERT_EQ(evaluation->gradients->constraint_rows.size(), 1u);
  EXPECT_DOUBLE_EQ(evaluation->gradients->constraint_rows[0][0], 2 * (1 + c));

  // And the same objective gradient, bit for bit, as from the JSON driver.
  ExternalWorkerSettings json_settings;
  TempDir json_base;
  json_settings.drivers = {ProductDriver(json_base, kProductJsonScript, ResultsFormat::kJson)};
  json_settings.work_directory = work_.path() / "json-runs";
  const spec::Study json_study = ReadStudy(kProductStudy);
  const ExternalSceneAnalyzer json_analyzer(json_settings, "t");
  absl::StatusOr<engine::StudyEvaluation> from_json =
      engine::EvaluateStudy(json_study, *spec::MakeStudyLayout(json_study), {x}, true, &json_analyzer);
  ASSERT_TRUE(from_json.ok() && from_json->gradients.has_value());
  EXPECT_EQ(from_json->gradients->objective_terms[0][0], evaluation->gradients->objective_terms[0][0]);
}

TEST_F(ExternalSceneAnalysis, ADriverWithoutTheGradientsAStudyAsksForFailsNamingDriverAndFile) {
  settings_.drivers = {ProductDriver(base_, R"(. ./input.sh
printf '{"values": {"f": 1}, "series": {"y": [1, 2, 3]}}' > results.json
)", ResultsFormat::kJson)};
  const spec::Study study = ReadStudy(kProductStudy);
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  const ExternalSceneAnalyzer analyzer(settings_, "t");
  absl::StatusOr<engine::StudyEvaluation> evaluation =
      engine::EvaluateStudy(study, *layout, {0.7}, /*want_gradients=*/true, &analyzer);
  ASSERT_TRUE(evaluation.ok()) << evaluation.status();
  EXPECT_EQ(evaluation->failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_THAT(evaluation->failure.reason,
              AllOf(HasSubstr("driver \"product\""), HasSubstr("results.json: no gradient of value \"f\""),
                    HasSubstr("with respect to parameter \"a\""), HasSubstr("SENSITIVITY_METHOD_SIMULATOR")));
  // Without gradients asked for, the same driver is fine.
  absl::StatusOr<engine::StudyEvaluation> plain =
      engine::EvaluateStudy(study, *layout, {0.7}, /*want_gradients=*/false, &analyzer);
  ASSERT_TRUE(plain.ok()) << plain.status();
  EXPECT_TRUE(plain->ok()) << plain->failure.reason;
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
