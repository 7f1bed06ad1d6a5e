// The `external` scene kind as spec/io reads it: a driver's name, inputs
// bound to scene parameters, and outputs that name the driver's results.
// Problems name the line and the field; what only a worker knows (the
// driver's declared parameters) is checked there (tests/external).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "spec/layout.h"

namespace mbopt::spec::io {
namespace {

using ::testing::HasSubstr;

const char kStudy[] = R"pb(name: "spring study"
scene {
  name: "spring"
  parameters { name: "k" value: 2 unit: "kN/m" }
  parameters { name: "c" value: 10 }
  external {
    driver: "spring-sim"
    inputs { name: "stiffness" value { param: "k" } }
    inputs { name: "damping" value { expr: "2 * c" } }
  }
  outputs { name: "x" external_series { name: "x_m" } }
  outputs { name: "peak" external_value { name: "peak_force_n" } }
  time_grid { start_s: 0 end_s: 1 points: 11 }
}
variables { name: "k" parameter: "k" scale: 1 initial: 2 lower: 1 upper: 5 }
objective { minimize: "peak" }
constraints { name: "travel" output: "x" reduction: REDUCTION_MAX_ABS limit: 5 unit: "mm" }
)pb";

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test setup: \"" << from << "\" not in the text";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

absl::StatusOr<Study> Read(const std::string& text) {
  absl::StatusOr<v1::Study> message = ParseStudyText(text, "spring.study.textproto");
  if (!message.ok()) return message.status();
  return StudyFromProto(*message, "spring.study.textproto");
}

std::string ParseError(const std::string& text) {
  absl::StatusOr<v1::Study> message = ParseStudyText(text, "spring.study.textproto");
  EXPECT_FALSE(message.ok());
  return message.ok() ? "" : std::string(message.status().message());
}

TEST(ExternalScene, NamesTheDriverAndBindsItsInputsToSceneParameters) {
  absl::StatusOr<Study> study = Read(kStudy);
  ASSERT_TRUE(study.ok()) << study.status();
  const auto* model = std::get_if<ExternalModel>(&study->scene.model);
  ASSERT_NE(model, nullptr);
  EXPECT_EQ(model->driver, "spring-sim");
  ASSERT_EQ(model->inputs.size(), 2u);
  EXPECT_EQ(model->inputs[0].name, "stiffness");
  EXPECT_EQ(model->inputs[1].name, "damping");
  // k in kN/m reaches the driver in SI; an expression is evaluated per design.
  const std::vector<double> at = study->ParameterValuesAt({3.0});
  EXPECT_DOUBLE_EQ(model->inputs[0].value.Resolve(at), 3000.0);
  EXPECT_DOUBLE_EQ(model->inputs[1].value.Resolve(at), 20.0);
}

TEST(ExternalScene, AValueIsAScalarOutputAndASeriesLivesOnTheGrid) {
  absl::StatusOr<Study> study = Read(kStudy);
  ASSERT_TRUE(study.ok()) << study.status();
  const auto* series = std::get_if<ExternalResultOutput>(&study->scene.outputs[0].kind);
  const auto* value = std::get_if<ExternalResultOutput>(&study->scene.outputs[1].kind);
  ASSERT_NE(series, nullptr);
  ASSERT_NE(value, nullptr);
  EXPECT_EQ(series->name, "x_m");
  EXPECT_TRUE(series->series);
  EXPECT_EQ(value->name, "peak_force_n");
  EXPECT_FALSE(value->series);
  absl::StatusOr<StudyLayout> layout = MakeStudyLayout(*study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  EXPECT_TRUE(layout->outputs[1].scalar);
  EXPECT_FALSE(layout->outputs[0].scalar);
  EXPECT_EQ(layout->outputs[0].instants, 11);
  // Two rows (x <= limit, -x <= limit) per grid instant for the travel
  // limit, as with any series.
  EXPECT_EQ(layout->rows.size(), 22u);
}

TEST(ExternalScene, WindowOnAValueIsRefusedAsOnAnyScalar) {
  const std::string text = Replace(kStudy, R"(objective { minimize: "peak" })",
                                   R"(objective { minimize: "peak" reduction: REDUCTION_RMS })");
  absl::StatusOr<Study> study = Read(text);
  ASSERT_FALSE(study.ok());
  EXPECT_THAT(study.status().message(), HasSubstr("an external value"));
}

TEST(ExternalScene, MissingOrUnsafeDriverNameIsNamedWithItsLine) {
  EXPECT_THAT(ParseError(Replace(kStudy, R"(driver: "spring-sim")", "")),
              AllOf(HasSubstr("spring.study.textproto:6:"), HasSubstr("scene.external.driver"),
                    HasSubstr("expected the name of an analysis driver")));
  EXPECT_THAT(ParseError(Replace(kStudy, R"(driver: "spring-sim")", R"(driver: "../bin/sh")")),
              AllOf(HasSubstr("spring.study.textproto:7:"), HasSubstr("scene.external.driver"),
                    HasSubstr("\"../bin/sh\" is not a driver name")));
}

TEST(ExternalScene, UnknownParameterAndDuplicateInputAreNamed) {
  EXPECT_THAT(ParseError(Replace(kStudy, R"(value { param: "k" })", R"(value { param: "kk" })")),
              AllOf(HasSubstr("spring.study.textproto:8:"), HasSubstr("scene.external.inputs[0].value"),
                    HasSubstr("unknown parameter \"kk\"")));
  EXPECT_THAT(ParseError(Replace(kStudy, R"(inputs { name: "damping")", R"(inputs { name: "stiffness")")),
              AllOf(HasSubstr("scene.external.inputs[1].name"), HasSubstr("duplicate input \"stiffness\"")));
}

TEST(ExternalScene, OutputsOfOtherModelsAndExternalOutputsElsewhereAreRefused) {
  EXPECT_THAT(ParseError(Replace(kStudy, R"(external_series { name: "x_m" })", "mass {}")),
              HasSubstr("output \"x\" needs a linkage model; this scene's model is external"));
  const std::string lumped = Replace(Replace(kStudy, R"(external {
    driver: "spring-sim"
    inputs { name: "stiffness" value { param: "k" } }
    inputs { name: "damping" value { expr: "2 * c" } }
  })",
                                             R"(lumped { bodies { name: "b" mass_kg { value: 1 } dofs: [DOF_Y] } })"),
                                     R"(external_value { name: "peak_force_n" })", R"(external_value { name: "" })");
  const std::string error = ParseError(lumped);
  EXPECT_THAT(error, HasSubstr("output \"x\" needs an external model; this scene's model is lumped"));
  EXPECT_THAT(error, HasSubstr("scene.outputs[1].external_value.name"));
}

TEST(ExternalScene, EffectsAreTheDriversNotTheScenes) {
  EXPECT_THAT(ParseError(Replace(kStudy, R"(  external {)", R"(  effects { gravity {} }
  external {)")),
              HasSubstr("an external scene's effects are its driver's"));
}

// The driver's gradients are the simulator's sensitivities
// (worker/external); whether it writes them shows in its results.
TEST(ExternalScene, SimulatorSensitivitiesAreAcceptedAsTheDriversGradients) {
  absl::StatusOr<Study> study = Read(std::string(kStudy) + "optimizer { sensitivity: SENSITIVITY_METHOD_SIMULATOR }\n");
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_TRUE(study->optimizer.simulator_sensitivities);
}

}  // namespace
}  // namespace mbopt::spec::io
