// FMI 3.0 model descriptions: what is read, and the features mbopt refuses
// with the variable or element named.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "worker/fmu/model_description.h"

namespace mbopt::fmu {
namespace {

using ::testing::HasSubstr;

// A description with `body` inside the root element (which is line 1).
std::string Fmi3(const std::string& body) {
  return "<fmiModelDescription fmiVersion=\"3.0\" modelName=\"m\" instantiationToken=\"{t}\">\n" + body +
         "\n</fmiModelDescription>";
}

std::string Refusal(const std::string& body) {
  auto description = ParseModelDescription(Fmi3(body), "md.xml");
  EXPECT_FALSE(description.ok());
  return description.ok() ? "" : std::string(description.status().message());
}

TEST(Fmi3ModelDescription, ReadsFloat64VariablesStatesAndEventIndicatorsByValueReference) {
  auto description = ParseModelDescription(Fmi3(R"xml(<ModelExchange modelIdentifier="m"
    providesDirectionalDerivatives="true"/>
<CoSimulation modelIdentifier="m" canHandleVariableCommunicationStepSize="true"/>
<DefaultExperiment stopTime="2" stepSize="0.01"/>
<ModelVariables>
  <Float64 name="time" valueReference="9" causality="independent"/>
  <Float64 name="v" valueReference="4"/>
  <Float64 name="x" valueReference="3" causality="output" start="0.5"/>
  <Float64 name="der(x)" valueReference="7" derivative="3"/>
  <Float64 name="der(v)" valueReference="8" derivative="4"/>
  <Float64 name="k" valueReference="1" causality="parameter" variability="tunable" start="2"/>
  <Int32 name="counter" valueReference="2"/>
</ModelVariables>
<ModelStructure>
  <Output valueReference="3"/>
  <ContinuousStateDerivative valueReference="8"/>
  <ContinuousStateDerivative valueReference="7"/>
  <EventIndicator valueReference="3"/>
</ModelStructure>)xml"),
                                           "md.xml");
  ASSERT_TRUE(description.ok()) << description.status();
  EXPECT_EQ(description->fmi_major_version, 3);
  EXPECT_EQ(description->guid, "{t}");
  ASSERT_TRUE(description->model_exchange.has_value());
  EXPECT_TRUE(description->model_exchange->provides_directional_derivative);
  ASSERT_TRUE(description->co_simulation.has_value());
  EXPECT_FALSE(description->co_simulation->provides_directional_derivative);
  EXPECT_EQ(description->default_experiment.step_size_s, 0.01);
  EXPECT_EQ(description->Find("x")->type, VariableType::kReal);
  EXPECT_EQ(description->Find("x")->start, 0.5);
  EXPECT_EQ(description->Find("k")->causality, Causality::kParameter);
  EXPECT_EQ(description->Find("k")->variability, Variability::kTunable);
  EXPECT_EQ(description->Find("counter")->type, VariableType::kInteger);
  // States in the order of <ContinuousStateDerivative>, found through `derivative`.
  EXPECT_EQ(description->derivative_indices, (std::vector<int>{4, 3}));
  EXPECT_EQ(description->state_indices, (std::vector<int>{1, 2}));
  EXPECT_EQ(description->number_of_event_indicators, 1);
}

TEST(Fmi3ModelDescription, RefusesClocksNamingTheVariable) {
  EXPECT_THAT(Refusal(R"xml(<ModelExchange modelIdentifier="m"/>
<ModelVariables>
  <Clock name="tick" valueReference="1" causality="input" intervalVariability="constant"/>
</ModelVariables>)xml"),
              HasSubstr("md.xml:4: <Clock name=\"tick\">: clocks are not supported"));
  EXPECT_THAT(Refusal(R"xml(<ModelExchange modelIdentifier="m"/>
<ModelVariables>
  <Float64 name="sampled" valueReference="2" clocks="1"/>
</ModelVariables>)xml"),
              HasSubstr("<Float64 name=\"sampled\">: attribute clocks: clocked variables are not supported"));
}

TEST(Fmi3ModelDescription, RefusesArrays) {
  EXPECT_THAT(Refusal(R"xml(<ModelExchange modelIdentifier="m"/>
<ModelVariables>
  <Float64 name="xs" valueReference="1" start="0 0 0"><Dimension start="3"/></Float64>
</ModelVariables>)xml"),
              HasSubstr("md.xml:4: <Float64 name=\"xs\">: <Dimension>: array variables are not supported"));
  EXPECT_THAT(Refusal(R"xml(<ModelExchange modelIdentifier="m"/>
<ModelVariables>
  <UInt64 name="n" valueReference="1" causality="structuralParameter" variability="fixed" start="3"/>
</ModelVariables>)xml"),
              HasSubstr("<UInt64 name=\"n\">: attribute causality: structural parameters"));
}

TEST(Fmi3ModelDescription, RefusesParametersAndOutputsOfOtherTypesThanFloat64) {
  EXPECT_THAT(Refusal(R"xml(<ModelExchange modelIdentifier="m"/>
<ModelVariables>
  <Int32 name="gear" valueReference="1" causality="parameter" variability="fixed" start="2"/>
</ModelVariables>)xml"),
              HasSubstr("<Int32 name=\"gear\">: a parameter of type Int32 is not supported: mbopt sets and reads "
                        "Float64 variables only"));
  EXPECT_THAT(Refusal(R"xml(<CoSimulation modelIdentifier="m"/>
<ModelVariables>
  <Float32 name="y" valueReference="1" causality="output"/>
</ModelVariables>)xml"),
              HasSubstr("<Float32 name=\"y\">: an output of type Float32 is not supported"));
}

TEST(Fmi3ModelDescription, RefusesScheduledExecutionOnly) {
  EXPECT_THAT(Refusal(R"xml(<ScheduledExecution modelIdentifier="m"/>
<ModelVariables/>)xml"),
              HasSubstr("md.xml:2: <ScheduledExecution>: Scheduled Execution is not supported"));
}

TEST(Fmi3ModelDescription, RefusesADerivativeOfNoVariableAndDuplicateValueReferences) {
  EXPECT_THAT(Refusal(R"xml(<ModelExchange modelIdentifier="m"/>
<ModelVariables>
  <Float64 name="x" valueReference="1"/>
</ModelVariables>
<ModelStructure><ContinuousStateDerivative valueReference="1"/></ModelStructure>)xml"),
              HasSubstr("md.xml:6: <ContinuousStateDerivative>: attribute valueReference: variable \"x\" is not a "
                        "<Float64 derivative=\"...\">"));
  EXPECT_THAT(Refusal(R"xml(<ModelExchange modelIdentifier="m"/>
<ModelVariables>
  <Float64 name="x" valueReference="1"/>
  <Float64 name="y" valueReference="1"/>
</ModelVariables>)xml"),
              HasSubstr("<Float64 name=\"y\">: attribute valueReference: 1 is already \"x\"'s"));
}

TEST(Fmi3ModelDescription, RefusesAMissingInstantiationToken) {
  auto description = ParseModelDescription(
      "<fmiModelDescription fmiVersion=\"3.0\" modelName=\"m\">\n<ModelExchange modelIdentifier=\"m\"/>\n"
      "<ModelVariables/>\n</fmiModelDescription>",
      "md.xml");
  ASSERT_FALSE(description.ok());
  EXPECT_THAT(description.status().message(), HasSubstr("attribute instantiationToken: expected the FMU's token"));
}

}  // namespace
}  // namespace mbopt::fmu
