// spec/io: good files load; every kind of bad input gives an InvalidArgument
// that names the file, the line and the field path, and says what was
// expected.
#include "spec/io/study_io.h"

#include <filesystem>
#include <fstream>

#include <google/protobuf/util/json_util.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/layout.h"
#include "spec/limits.h"
#include "tests/spec/oscillator_scene.h"

namespace mbopt::spec::io {
namespace {

using ::testing::HasSubstr;

// A one-body scene; tests replace pieces of it to break one thing at a time.
const char* const kScene = ::mbopt::testing::kOscillatorScene;

const char kStudy[] = R"pb(name: "oscillator study"
scene_file: "oscillator.scene.textproto"
variables { name: "x1" parameter: "k" scale: 10 lower: 5 upper: 20 }
objective { minimize_max_of: "acc" reduction: REDUCTION_MAX_ABS unit: "m/s^2" }
constraints { name: "travel" output: "x" reduction: REDUCTION_MAX_ABS limit: 5 unit: "mm" }
)pb";

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test setup: \"" << from << "\" not in the text";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// 1-based line of the first occurrence of `needle`.
int LineOf(const std::string& text, const std::string& needle) {
  const size_t at = text.find(needle);
  EXPECT_NE(at, std::string::npos);
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
}

class StudyFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    dir_ = std::filesystem::path(::testing::TempDir()) / ("spec_io_" + test);
    std::filesystem::create_directories(dir_);
  }
  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  // Loads the study with the given scene and study texts; expects failure.
  std::string LoadError(const std::string& scene, const std::string& study) {
    Write("oscillator.scene.textproto", scene);
    auto loaded = LoadStudyFile(Write("oscillator.study.textproto", study));
    EXPECT_FALSE(loaded.ok());
    if (loaded.ok()) return "";
    EXPECT_EQ(loaded.status().code(), absl::StatusCode::kInvalidArgument) << loaded.status();
    return std::string(loaded.status().message());
  }
  std::string ScenePath() const { return (dir_ / "oscillator.scene.textproto").string(); }
  std::string StudyPath() const { return (dir_ / "oscillator.study.textproto").string(); }
  std::string SceneAt(const std::string& needle, const std::string& scene = kScene) const {
    return ScenePath() + ":" + std::to_string(LineOf(scene, needle)) + ":";
  }
  std::string StudyAt(const std::string& needle, const std::string& study = kStudy) const {
    return StudyPath() + ":" + std::to_string(LineOf(study, needle)) + ":";
  }
  std::filesystem::path dir_;
};

TEST_F(StudyFiles, GoodStudyLoadsWithUnitsConvertedAndSceneResolvedRelativeToIt) {
  Write("oscillator.scene.textproto", kScene);
  auto study = LoadStudyFile(Write("oscillator.study.textproto", kStudy));
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_EQ(study->name, "oscillator study");
  ASSERT_EQ(study->variables.size(), 1u);
  EXPECT_EQ(study->variables[0].parameter, 0);
  EXPECT_DOUBLE_EQ(study->variables[0].initial, 10.0);  // 100 N/m / scale 10
  EXPECT_DOUBLE_EQ(study->constraints[0].si_per_unit, 1e-3);
  EXPECT_EQ(study->scene.outputs.size(), 2u);
  const auto& lumped = std::get<LumpedModel>(study->scene.model);
  EXPECT_EQ(lumped.elements[0].a.kind, Attachment::Kind::kBody);
  EXPECT_EQ(lumped.elements[0].b.kind, Attachment::Kind::kInput);
  EXPECT_EQ(lumped.bodies[0].mass_kg.param, 1);
  // x = 12 (scaled) -> k = 120 N/m in SI.
  EXPECT_DOUBLE_EQ(study->ParameterValuesAt({12.0})[0], 120.0);
}

TEST_F(StudyFiles, OverridesApplyToTheScene) {
  Write("oscillator.scene.textproto", kScene);
  auto study = LoadStudyFile(Write(
      "oscillator.study.textproto",
      std::string(kStudy) + "analysis { time_grid_points: 21 relative_tolerance: 1e-9 }\n"));
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_EQ(study->scene.time_grid.points, 21);
  EXPECT_EQ(study->scene.integrator.relative_tolerance, 1e-9);
}

TEST_F(StudyFiles, ReadStudyProtoInlinesTheSceneAndStudyFromProtoAgrees) {
  Write("oscillator.scene.textproto", kScene);
  auto message = ReadStudyProto(Write("oscillator.study.textproto", kStudy));
  ASSERT_TRUE(message.ok()) << message.status();
  EXPECT_TRUE(message->has_scene());
  EXPECT_EQ(message->scene().name(), "oscillator");
  auto study = StudyFromProto(*message, "submitted");
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_EQ(study->scene.outputs.size(), 2u);
  EXPECT_EQ(study->source_file, "submitted");
}

TEST_F(StudyFiles, StudyFromProtoNamesTheFieldWithoutLineNumbers) {
  Write("oscillator.scene.textproto", kScene);
  auto message = ReadStudyProto(Write("oscillator.study.textproto", kStudy));
  ASSERT_TRUE(message.ok());
  message->mutable_variables(0)->set_lower(30);
  auto study = StudyFromProto(*message, "request");
  ASSERT_FALSE(study.ok());
  EXPECT_THAT(std::string(study.status().message()), HasSubstr("request: variables[0].upper"));
  message->clear_scene();
  EXPECT_THAT(std::string(StudyFromProto(*message, "request").status().message()),
              HasSubstr("inline"));
}

TEST_F(StudyFiles, VehicleExampleLoads) {
  auto study = LoadStudyFile("examples/vehicle/vehicle.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_EQ(study->variables.size(), 6u);
  EXPECT_EQ(study->constraints.size(), 5u);
  EXPECT_EQ(study->scene.time_grid.points, 101);
  EXPECT_FALSE(study->scene.effects.gravity_m_per_s2.has_value());
}

TEST_F(StudyFiles, SyntaxErrorNamesFileLineAndColumn) {
  const std::string scene = Replace(kScene, "dofs: DOF_Y }", "dofs: DOF_Y ");
  const std::string error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr(ScenePath() + ":"));
  EXPECT_THAT(error, ::testing::ContainsRegex(":[0-9]+:[0-9]+: "));
}

// The scene file given where the study belongs: said as such, not as the
// scene's first field unknown to a study.
TEST_F(StudyFiles, SceneFileGivenAsTheStudyIsNamedAsSuch) {
  auto loaded = LoadStudyFile(Write("oscillator.scene.textproto", kScene));
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.status().code(), absl::StatusCode::kInvalidArgument);
  const std::string error(loaded.status().message());
  EXPECT_THAT(error, HasSubstr(ScenePath() + ": this is a scene file, and a study is expected here"));
  EXPECT_THAT(error, HasSubstr("scene_file: \"oscillator.scene.textproto\""));
  // A study with a real mistake keeps its own message.
  const std::string typo = LoadError(kScene, Replace(kStudy, "name:", "nmae:"));
  EXPECT_THAT(typo, ::testing::Not(HasSubstr("this is a scene file")));
  EXPECT_THAT(typo, HasSubstr("nmae"));
}

TEST_F(StudyFiles, UnknownFieldIsASyntaxErrorWithItsLine) {
  const std::string scene = Replace(kScene, "dofs: DOF_Y", "dofs: DOF_Y colour: 3");
  const std::string error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr(SceneAt("colour", scene)));
  EXPECT_THAT(error, HasSubstr("colour"));
}

TEST_F(StudyFiles, UnknownParameterNameIsReportedAtItsField) {
  const std::string scene = Replace(kScene, "{ param: \"k\" }", "{ param: \"kx\" }");
  const std::string error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr(SceneAt("stiffness_n_per_m", scene)));
  EXPECT_THAT(error, HasSubstr("lumped.elements[0].stiffness_n_per_m"));
  EXPECT_THAT(error, HasSubstr("unknown parameter \"kx\""));
}

TEST_F(StudyFiles, ParameterWithTheWrongKindOfUnitIsRejected) {
  const std::string scene = Replace(kScene, "unit: \"N/m\"", "unit: \"mm\"");
  const std::string error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr("lumped.elements[0].stiffness_n_per_m"));
  EXPECT_THAT(error, HasSubstr("\"mm\" (length)"));
}

TEST_F(StudyFiles, UnknownUnitIsReportedAtTheParameter) {
  const std::string scene = Replace(kScene, "unit: \"N/m\"", "unit: \"N/furlong\"");
  const std::string error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr(SceneAt("N/furlong", scene)));
  EXPECT_THAT(error, HasSubstr("parameters[0].unit"));
  EXPECT_THAT(error, HasSubstr("unknown unit \"N/furlong\""));
}

TEST_F(StudyFiles, ReversedBoundsAreReportedAtTheVariable) {
  const std::string study = Replace(kStudy, "lower: 5 upper: 20", "lower: 20 upper: 5");
  const std::string error = LoadError(kScene, study);
  EXPECT_THAT(error, HasSubstr(StudyAt("x1", study)));
  EXPECT_THAT(error, HasSubstr("variables[0].upper"));
  EXPECT_THAT(error, HasSubstr("bounds reversed"));
}

TEST_F(StudyFiles, InitialOutsideBoundsIsReported) {
  const std::string study = Replace(kStudy, "lower: 5", "initial: 50 lower: 5");
  const std::string error = LoadError(kScene, study);
  EXPECT_THAT(error, HasSubstr("variables[0].initial"));
  EXPECT_THAT(error, HasSubstr("outside the bounds [5, 20]"));
}

TEST_F(StudyFiles, DefaultInitialFromTheParameterMustAlsoBeInsideTheBounds) {
  const std::string study = Replace(kStudy, "lower: 5 upper: 20", "lower: 15 upper: 20");
  const std::string error = LoadError(kScene, study);
  EXPECT_THAT(error, HasSubstr("variables[0].parameter"));
  EXPECT_THAT(error, HasSubstr("initial value 10"));
}

TEST_F(StudyFiles, UnknownDesignParameterIsReported) {
  const std::string study = Replace(kStudy, "parameter: \"k\"", "parameter: \"stiffness\"");
  const std::string error = LoadError(kScene, study);
  EXPECT_THAT(error, HasSubstr(StudyAt("parameter:", study)));
  EXPECT_THAT(error, HasSubstr("variables[0].parameter"));
  EXPECT_THAT(error, HasSubstr("unknown scene parameter \"stiffness\""));
}

TEST_F(StudyFiles, MissingBodyReferenceIsReportedAtTheAttachment) {
  const std::string scene = Replace(kScene, "a { body: \"body\" }", "a { body: \"chassis\" }");
  const std::string error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr(SceneAt("chassis", scene)));
  EXPECT_THAT(error, HasSubstr("lumped.elements[0].a.body"));
  EXPECT_THAT(error, HasSubstr("unknown body \"chassis\""));
}

TEST_F(StudyFiles, MissingInputAndElementReferencesAreReported) {
  std::string scene = Replace(kScene, "b { input: \"road\" }", "b { input: \"track\" }");
  scene = Replace(scene, "element: \"spring\"", "element: \"coil\"");
  const std::string error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr("lumped.elements[0].b.input: unknown input \"track\""));
  EXPECT_THAT(error, HasSubstr("outputs[0].element_deflection.element: unknown element \"coil\""));
}

TEST_F(StudyFiles, ZeroDirectionIsRejected) {
  const std::string scene = Replace(kScene, "direction { y { value: 1 } }\n    stiffness",
                                    "direction { }\n    stiffness");
  const std::string error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr("lumped.elements[0].direction"));
  EXPECT_THAT(error, HasSubstr("zero direction vector"));
}

TEST_F(StudyFiles, NegativeMassIsRejected) {
  const std::string scene = Replace(kScene, "name: \"mass\" value: 2", "name: \"mass\" value: -2");
  const std::string error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr(SceneAt("mass_kg", scene)));
  EXPECT_THAT(error, HasSubstr("lumped.bodies[0].mass_kg: must be positive, got -2"));
}

TEST_F(StudyFiles, TimeGridWithoutPointsOrRunningBackwardsIsRejected) {
  std::string scene = Replace(kScene, "points: 11", "points: 0");
  std::string error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr(SceneAt("time_grid", scene)));
  EXPECT_THAT(error, HasSubstr("time_grid.points: must be at least 1, got 0"));
  scene = Replace(kScene, "end_s: 1", "end_s: -1");
  error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr("time_grid.end_s: must be >= start_s"));
}

TEST_F(StudyFiles, MissingModelIsRejected) {
  const size_t begin = std::string(kScene).find("lumped {");
  const size_t end = std::string(kScene).find("outputs {");
  std::string scene = kScene;
  scene.erase(begin, end - begin);
  const std::string error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr("no model"));
}

TEST_F(StudyFiles, UnknownOutputInConstraintListsTheSceneOutputs) {
  const std::string study = Replace(kStudy, "output: \"x\"", "output: \"travel\"");
  const std::string error = LoadError(kScene, study);
  EXPECT_THAT(error, HasSubstr(StudyAt("constraints", study)));
  EXPECT_THAT(error, HasSubstr("constraints[0].output: unknown output \"travel\""));
  EXPECT_THAT(error, HasSubstr("\"x\", \"acc\""));
}

TEST_F(StudyFiles, PlotsNameSignalsWithTheirUnits) {
  Write("oscillator.scene.textproto", kScene);
  auto study = LoadStudyFile(Write("oscillator.study.textproto",
                                   std::string(kStudy) + "plots { x: \"x\" y: \"acc\" x_unit: \"mm\" }\n"));
  ASSERT_TRUE(study.ok()) << study.status();
  ASSERT_EQ(study->plots.size(), 1u);
  EXPECT_EQ(study->SignalName(study->plots[0].x), "x");
  EXPECT_EQ(study->SignalName(study->plots[0].y), "acc");
  EXPECT_DOUBLE_EQ(study->plots[0].x_si_per_unit, 1e-3);
  EXPECT_DOUBLE_EQ(study->plots[0].y_si_per_unit, 1.0);  // no unit: SI
}

TEST_F(StudyFiles, PlotOfAnUnknownOutputListsTheNamesThatExist) {
  const std::string study = std::string(kStudy) + "plots {\n  x: \"x\"\n  y: \"crank_angle\"\n}\n";
  const std::string error = LoadError(kScene, study);
  EXPECT_THAT(error, HasSubstr(StudyPath() + ":" + std::to_string(LineOf(study, "y: \"crank_angle\"")) + ":"));
  EXPECT_THAT(error, HasSubstr("plots[0].y: unknown output \"crank_angle\""));
  EXPECT_THAT(error, HasSubstr("\"x\", \"acc\""));
}

TEST_F(StudyFiles, TooManyPlotsAreRefused) {
  std::string study = kStudy;
  for (int i = 0; i <= kMaxXyPlots; ++i) study += "plots { x: \"x\" y: \"acc\" }\n";
  EXPECT_THAT(LoadError(kScene, study), HasSubstr("101 plots, more than the limit of 100"));
}

TEST_F(StudyFiles, PlotUnitMustFitItsSignal) {
  const std::string study = std::string(kStudy) + "plots { x: \"x\" y: \"acc\" y_unit: \"mm\" }\n";
  const std::string error = LoadError(kScene, study);
  EXPECT_THAT(error, HasSubstr("plots[0].y_unit"));
  EXPECT_THAT(error, HasSubstr("length but the output is a acceleration"));
}

TEST_F(StudyFiles, ConstraintUnitMustFitTheOutput) {
  const std::string study = Replace(kStudy, "unit: \"mm\"", "unit: \"m/s^2\"");
  const std::string error = LoadError(kScene, study);
  EXPECT_THAT(error, HasSubstr("constraints[0].unit"));
  EXPECT_THAT(error, HasSubstr("acceleration but the output is a length"));
}

TEST_F(StudyFiles, ObjectiveNeedsAReductionThatMakesAMaximum) {
  const std::string study = Replace(kStudy, "reduction: REDUCTION_MAX_ABS unit: \"m/s^2\"",
                                    "reduction: REDUCTION_MIN unit: \"m/s^2\"");
  const std::string error = LoadError(kScene, study);
  EXPECT_THAT(error, HasSubstr(StudyAt("objective", study)));
  EXPECT_THAT(error, HasSubstr("objective.reduction"));
}

TEST_F(StudyFiles, OutputOfTheWrongModelKindIsRejected) {
  const std::string scene = std::string(kScene) + "outputs { name: \"m\" mass {} }\n";
  const std::string error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr("outputs[2]"));
  EXPECT_THAT(error, HasSubstr("needs a linkage model"));
}

TEST_F(StudyFiles, MissingSceneFileIsReportedAtTheStudyField) {
  const std::string study =
      Replace(kStudy, "oscillator.scene.textproto", "nowhere.scene.textproto");
  const std::string error = LoadError(kScene, study);
  EXPECT_THAT(error, HasSubstr(StudyAt("scene_file", study)));
  EXPECT_THAT(error, HasSubstr("cannot open scene file"));
}

TEST_F(StudyFiles, SeveralErrorsAreReportedTogether) {
  std::string scene = Replace(kScene, "{ param: \"k\" }", "{ param: \"kx\" }");
  scene = Replace(scene, "points: 11", "points: 0");
  const std::string error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr("unknown parameter \"kx\""));
  EXPECT_THAT(error, HasSubstr("time_grid.points"));
}

TEST_F(StudyFiles, LinkageReferencesAreChecked) {
  const std::string scene = R"pb(name: "bad linkage"
linkage {
  joints { name: "O2" ground: true position_m { x { value: 0 } y { value: 0 } } }
  joints { name: "A" position_m { x { value: 0 } y { value: 0.1 } } }
  links { name: "crank" joint_a: "O2" joint_b: "B" }
  driver { link: "crank" pivot_joint: "A" angular_velocity_rad_per_s { value: 10 } }
}
outputs { name: "angle" link_rotation { link: "rocker" } }
time_grid { start_s: 0 end_s: 1 points: 2 }
)pb";
  Write("linkage.scene.textproto", scene);
  auto loaded = LoadSceneFile((dir_ / "linkage.scene.textproto").string());
  ASSERT_FALSE(loaded.ok());
  const std::string error(loaded.status().message());
  EXPECT_THAT(error, HasSubstr("linkage.links[0].joint_b: unknown joint \"B\""));
  EXPECT_THAT(error, HasSubstr("linkage.driver.pivot_joint"));
  EXPECT_THAT(error, HasSubstr("outputs[0].link_rotation.link: unknown link \"rocker\""));
}

TEST_F(StudyFiles, JsonStudyLoadsLikeTheTextOne) {
  auto message = ReadStudyProto("examples/vehicle/vehicle.study.textproto");
  ASSERT_TRUE(message.ok()) << message.status();
  std::string json;
  ASSERT_TRUE(google::protobuf::util::MessageToJsonString(*message, &json).ok());
  auto study = LoadStudyFile(Write("vehicle.study.json", json));
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_EQ(study->variables.size(), 6u);
  EXPECT_EQ(study->scene.outputs.size(), 6u);
  auto broken = LoadStudyFile(Write("broken.study.json", "{\"name\": 3"));
  ASSERT_FALSE(broken.ok());
  EXPECT_THAT(std::string(broken.status().message()), HasSubstr("broken.study.json"));
}

TEST_F(StudyFiles, GravityInALumpedSceneIsRejectedNotIgnored) {
  const std::string gravity =
      "effects { gravity { acceleration_m_per_s2 { y { value: -9.81 } } } }\n";
  const std::string scene = std::string(kScene) + gravity;
  const std::string error = LoadError(scene, kStudy);
  EXPECT_THAT(error, HasSubstr(SceneAt("effects", scene)));
  EXPECT_THAT(error, HasSubstr("effects.gravity"));
}

// Resource limits (spec/limits.h): refused at load, naming the field and the
// limit, before anything of that size is allocated or read.
TEST_F(StudyFiles, DeviceOrDirectoryAsASceneFileIsNotARegularFile) {
  for (const char* path : {"/dev/zero", "/tmp"}) {
    auto loaded = LoadStudyFile(Write("oscillator.study.textproto",
                                      Replace(kStudy, "oscillator.scene.textproto", path)));
    ASSERT_FALSE(loaded.ok()) << path;
    EXPECT_THAT(loaded.status().message(), HasSubstr(std::string(path) + ": not a regular file"));
  }
}

TEST_F(StudyFiles, OversizedFileIsRefusedBeforeItIsRead) {
  Write("oscillator.scene.textproto", std::string(kScene) + std::string(kMaxInputFileBytes, '#'));
  auto loaded = LoadStudyFile(Write("oscillator.study.textproto", kStudy));
  ASSERT_FALSE(loaded.ok());
  EXPECT_THAT(loaded.status().message(), HasSubstr("larger than the 16 MB limit"));
}

TEST_F(StudyFiles, CountsAboveTheirLimitsAreNamed) {
  EXPECT_THAT(LoadError(kScene, std::string(kStudy) + "analysis { time_grid_points: 10000000 }\n"),
              HasSubstr("analysis.time_grid_points: 10000000 is more than the limit of 1000000 instants"));
  EXPECT_THAT(LoadError(Replace(kScene, "points: 11", "points: 2147483647"), kStudy),
              HasSubstr("time_grid.points: 2147483647 is more than the limit"));
  EXPECT_THAT(LoadError(kScene, std::string(kStudy) + "optimizer { max_cycles: 2147483647 }\n"),
              HasSubstr("optimizer.max_cycles: 2147483647 is more than the limit"));
}

// A server would refuse the message such a file becomes (proto3 strings are
// UTF-8): the file is refused first, naming the field and its line.
TEST_F(StudyFiles, TextThatIsNotUtf8IsRefusedNamingTheField) {
  EXPECT_THAT(LoadError(kScene, std::string(kStudy) + "description: \"caf\xe9\"\n"),
              HasSubstr(StudyPath() + ":" + std::to_string(LineOf(std::string(kStudy) + "description:", "description:")) +
                        ":1: description: text is not valid UTF-8"));
  EXPECT_THAT(LoadError(Replace(kScene, "name: \"", "name: \"\xff"), kStudy),
              HasSubstr("text is not valid UTF-8"));
  Write("oscillator.scene.textproto", kScene);
  EXPECT_TRUE(LoadStudyFile(Write("utf8.study.textproto", std::string(kStudy) + "description: \"caf\xc3\xa9\"\n")).ok())
      << "valid UTF-8 is accepted";
}

// A name is copied into every row of its constraint (a million at 10^5
// instants): a 100 KB study whose constraint had a 100,000-character name
// took a server to 2.4 GB. Names are bounded where a study is read, on the
// file path and on the server's, with the field and its line.
TEST_F(StudyFiles, LongNamesAreRefusedWhereTheStudyIsRead) {
  const std::string long_name(100'000, 'n');
  const std::string study = Replace(kStudy, "name: \"travel\"", "name: \"" + long_name + "\"");
  EXPECT_THAT(LoadError(kScene, study),
              HasSubstr(StudyAt("constraints {", study) + "15: constraints[0].name: a name of 100000 bytes, "
                        "more than the limit of 256"));
  EXPECT_THAT(LoadError(Replace(kScene, "name: \"k\"", "name: \"" + std::string(300, 'k') + "\""), kStudy),
              HasSubstr("name: a name of 300 bytes, more than the limit of 256"));
  // The server's path: a submitted message, without lines.
  Write("oscillator.scene.textproto", kScene);
  auto message = ReadStudyProto(Write("oscillator.study.textproto", kStudy));
  ASSERT_TRUE(message.ok()) << message.status();
  message->mutable_constraints(0)->set_name(long_name);
  auto submitted = StudyFromProto(*message, "request");
  ASSERT_FALSE(submitted.ok());
  EXPECT_THAT(std::string(submitted.status().message()),
              HasSubstr("request: constraints[0].name: a name of 100000 bytes"));
  // Other strings have a larger bound: a long description is fine, a
  // description over 64 KiB is not.
  Write("oscillator.scene.textproto", kScene);
  EXPECT_TRUE(LoadStudyFile(Write("long.study.textproto", std::string(kStudy) + "description: \"" +
                                                            std::string(10'000, 'd') + "\"\n"))
                  .ok());
  EXPECT_THAT(LoadError(kScene, std::string(kStudy) + "description: \"" + std::string(70'000, 'd') + "\"\n"),
              HasSubstr("description: text of 70000 bytes, more than the limit of 65536"));
}

TEST_F(StudyFiles, MemoryEstimateCountsTheConstraintNameInEveryRow) {
  Write("oscillator.scene.textproto", kScene);
  auto short_name = LoadStudyFile(Write("short.study.textproto", kStudy));
  auto long_name = LoadStudyFile(
      Write("long.study.textproto", Replace(kStudy, "name: \"travel\"", "name: \"" + std::string(206, 't') + "\"")));
  ASSERT_TRUE(short_name.ok() && long_name.ok());
  const StudyFootprint a = EstimateStudyFootprint(*short_name);
  const StudyFootprint b = EstimateStudyFootprint(*long_name);
  ASSERT_EQ(a.constraint_rows, b.constraint_rows);
  EXPECT_GT(a.constraint_rows, 0);
  EXPECT_EQ(b.memory_bytes - a.memory_bytes, a.constraint_rows * 200);
}

TEST_F(StudyFiles, OptimizerSettingsOutsideTheMethodsRangesAreRefusedAtLoad) {
  EXPECT_THAT(LoadError(kScene, std::string(kStudy) + "optimizer { initial_move_limit: 1e300 }\n"),
              HasSubstr("optimizer.initial_move_limit: must be at most 1"));
  EXPECT_THAT(LoadError(kScene, std::string(kStudy) + "optimizer { screening_threshold: nan }\n"),
              HasSubstr("optimizer.screening_threshold: must be finite"));
  EXPECT_THAT(LoadError(kScene, std::string(kStudy) + "optimizer { finite_difference_relative_step: 0.5 }\n"),
              HasSubstr("optimizer.finite_difference_relative_step: must be at most 0.1"));
  EXPECT_THAT(LoadError(kScene, std::string(kStudy) + "optimizer { convergence_optimality_tolerance: inf }\n"),
              HasSubstr("optimizer.convergence_optimality_tolerance"));
}

TEST_F(StudyFiles, StudyTooLargeForMemoryIsRefusedWithItsEstimate) {
  // The file's 11 instants: two objective terms and two constraint rows each.
  Write("oscillator.scene.textproto", kScene);
  auto small = LoadStudyFile(Write("oscillator.study.textproto", kStudy));
  ASSERT_TRUE(small.ok()) << small.status();
  const StudyFootprint f = EstimateStudyFootprint(*small);
  EXPECT_EQ(f.objective_terms, 22);
  EXPECT_EQ(f.constraint_rows, 22);
  EXPECT_GT(f.memory_bytes, 0);
  // 1e6 instants and ten such constraints: 2.2e7 values, about 4.4 GB.
  std::string study = std::string(kStudy) + "analysis { time_grid_points: 1000000 }\n";
  for (int k = 0; k < 10; ++k) {
    study += "constraints { name: \"c" + std::to_string(k) +
             "\" output: \"x\" reduction: REDUCTION_MAX_ABS limit: 5 unit: \"mm\" }\n";
  }
  const std::string error = LoadError(kScene, study);
  EXPECT_THAT(error, HasSubstr("GB of memory"));
  EXPECT_THAT(error, HasSubstr("more than the limit of 2 GB"));
  // Series count too: 200 responses of 1e6 instants in each of two load
  // cases need 3.2 GB before any row exists.
  std::string series = Replace(kStudy, "minimize_max_of: \"acc\"", "minimize_max_of: \"a.acc\"");
  series = Replace(series, "output: \"x\"", "output: \"a.x\"") +
           "analysis { time_grid_points: 1000000 }\ncases { name: \"a\" }\ncases { name: \"b\" }\n";
  for (int k = 0; k < 200; ++k) series += "responses { name: \"r" + std::to_string(k) + "\" expr: \"a.x * t\" }\n";
  EXPECT_THAT(LoadError(kScene, series), AllOf(HasSubstr("GB of series"), HasSubstr("fewer load cases and responses")));
}

TEST_F(StudyFiles, VariableThatSetsSeveralParametersGivesThemTheSameSiValue) {
  const std::string scene = Replace(kScene, "parameters { name: \"mass\" value: 2 unit: \"kg\" }",
                                    "parameters { name: \"mass\" value: 2 unit: \"kg\" }\n"
                                    "parameters { name: \"k_rear\" value: 1 unit: \"lbf/in\" }");
  Write("oscillator.scene.textproto", scene);
  const std::string study = Replace(kStudy, "parameter: \"k\"", "parameter: \"k\" also_sets: \"k_rear\"");
  auto loaded = LoadStudyFile(Write("oscillator.study.textproto", study));
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  const std::vector<double> p = loaded->ParameterValuesAt({12.0});
  EXPECT_DOUBLE_EQ(p[0], 120.0);  // N/m
  EXPECT_DOUBLE_EQ(p[2], 120.0);  // the same stiffness, whatever unit the scene wrote it in
  EXPECT_THAT(LoadError(scene, Replace(kStudy, "parameter: \"k\"", "parameter: \"k\" also_sets: \"nope\"")),
              HasSubstr("variables[0].also_sets[0]: unknown scene parameter \"nope\""));
  EXPECT_THAT(LoadError(scene, Replace(kStudy, "parameter: \"k\"", "parameter: \"k\" also_sets: \"k\"")),
              HasSubstr("already set by a variable"));
  // Simulator sensitivities sum the derivatives of the parameters set
  // (tests/sensitivity): the option loads.
  EXPECT_TRUE(
      LoadStudyFile(Write("oscillator.study.textproto", study + "optimizer { sensitivity: SENSITIVITY_METHOD_SIMULATOR }\n"))
          .ok());
}

TEST_F(StudyFiles, WeightedSumTermsCarryTheirOwnUnitsAndReductions) {
  const std::string objective = "objective { minimize_max_of: \"acc\" reduction: REDUCTION_MAX_ABS unit: \"m/s^2\" }";
  const std::string sum =
      "objective { minimize_sum { terms { output: \"acc\" reduction: REDUCTION_RMS window { from_s: 0.2 } "
      "unit: \"m/s^2\" } terms { output: \"x\" reduction: REDUCTION_RANGE weight: -2 unit: \"mm\" } } }";
  Write("oscillator.scene.textproto", kScene);
  auto loaded = LoadStudyFile(Write("oscillator.study.textproto", Replace(kStudy, objective, sum)));
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  ASSERT_EQ(loaded->objective.sum_terms.size(), 2u);
  EXPECT_EQ(loaded->objective.sum_terms[0].reduction, Reduction::kRms);
  EXPECT_EQ(loaded->objective.sum_terms[1].weight, -2.0);
  EXPECT_DOUBLE_EQ(loaded->objective.sum_terms[1].si_per_unit, 1e-3);
  auto layout = MakeStudyLayout(*loaded);
  ASSERT_TRUE(layout.ok()) << layout.status();
  EXPECT_EQ(layout->num_objective_terms(), 1);
  ASSERT_EQ(layout->sum_refs.size(), 2u);
  EXPECT_EQ(layout->sum_refs[0].first, 2);  // t = 0.2 s on the 11-point grid
  // A smallest value pushed down has no bound (StudyLanguage.SumOfPeaksRefusesPeaksItWouldRaise).
  EXPECT_THAT(LoadError(kScene, Replace(kStudy, objective,
                                        "objective { minimize_sum { terms { output: \"acc\" "
                                        "reduction: REDUCTION_MIN } } }")),
              HasSubstr("objective.minimize_sum.terms[0].weight: REDUCTION_MIN in a sum needs a negative weight"));
  EXPECT_THAT(LoadError(kScene, Replace(kStudy, objective,
                                        "objective { minimize_sum { terms { output: \"acc\" } } unit: \"m/s^2\" }")),
              HasSubstr("objective.unit: a weighted sum has no unit of its own"));
}

TEST_F(StudyFiles, MissingFileIsNotFound) {
  auto loaded = LoadSceneFile((dir_ / "absent.scene.textproto").string());
  EXPECT_EQ(loaded.status().code(), absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace mbopt::spec::io
