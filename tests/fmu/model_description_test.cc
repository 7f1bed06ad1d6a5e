#include "worker/fmu/model_description.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

namespace mbopt::fmu {
namespace {

using ::testing::HasSubstr;

std::string Description(const std::string& root_attributes, const std::string& body) {
  return "<?xml version=\"1.0\"?>\n<fmiModelDescription fmiVersion=\"2.0\" modelName=\"m\" guid=\"{g}\"" +
         root_attributes + ">\n" + body + "\n</fmiModelDescription>\n";
}

constexpr char kTwoStates[] = R"xml(<ModelExchange modelIdentifier="ball" providesDirectionalDerivative="true"/>
<CoSimulation modelIdentifier="ball_cs" canHandleVariableCommunicationStepSize="true"/>
<DefaultExperiment startTime="0.5" stopTime="3" tolerance="1e-6" stepSize="0.01"/>
<ModelVariables>
  <ScalarVariable name="h" valueReference="0" causality="output"><Real start="1"/></ScalarVariable>
  <ScalarVariable name="v" valueReference="1"><Real/></ScalarVariable>
  <ScalarVariable name="der(h)" valueReference="2"><Real derivative="1"/></ScalarVariable>
  <ScalarVariable name="der(v)" valueReference="3"><Real derivative="2"/></ScalarVariable>
  <ScalarVariable name="e" valueReference="4" causality="parameter" variability="tunable"><Real start="0.8"/></ScalarVariable>
  <ScalarVariable name="n" valueReference="0" causality="parameter" variability="fixed"><Integer start="3"/></ScalarVariable>
  <ScalarVariable name="on" valueReference="0" variability="discrete"><Boolean start="true"/></ScalarVariable>
</ModelVariables>
<ModelStructure>
  <Derivatives><Unknown index="4"/><Unknown index="3"/></Derivatives>
</ModelStructure>)xml";

TEST(ModelDescription, ReadsInterfacesVariablesStatesAndExperiment) {
  auto description = ParseModelDescription(Description(" numberOfEventIndicators=\"1\"", kTwoStates), "md.xml");
  ASSERT_TRUE(description.ok()) << description.status();
  EXPECT_EQ(description->fmi_version, "2.0");
  EXPECT_EQ(description->guid, "{g}");
  EXPECT_EQ(description->number_of_event_indicators, 1);
  ASSERT_TRUE(description->model_exchange.has_value());
  EXPECT_EQ(description->model_exchange->model_identifier, "ball");
  EXPECT_TRUE(description->model_exchange->provides_directional_derivative);
  ASSERT_TRUE(description->co_simulation.has_value());
  EXPECT_EQ(description->co_simulation->model_identifier, "ball_cs");
  EXPECT_FALSE(description->co_simulation->provides_directional_derivative);
  EXPECT_TRUE(description->co_simulation->can_handle_variable_communication_step_size);
  EXPECT_EQ(description->default_experiment.start_time_s, 0.5);
  EXPECT_EQ(description->default_experiment.step_size_s, 0.01);
  EXPECT_EQ(description->default_experiment.tolerance, 1e-6);

  ASSERT_EQ(description->variables.size(), 7u);
  const ScalarVariable* e = description->Find("e");
  ASSERT_NE(e, nullptr);
  EXPECT_EQ(e->value_reference, 4u);
  EXPECT_EQ(e->causality, Causality::kParameter);
  EXPECT_EQ(e->variability, Variability::kTunable);
  EXPECT_EQ(e->start, 0.8);
  EXPECT_EQ(description->Find("v")->causality, Causality::kLocal);  // the standard's default
  EXPECT_EQ(description->Find("v")->variability, Variability::kContinuous);
  EXPECT_FALSE(description->Find("v")->start.has_value());
  EXPECT_EQ(description->Find("n")->type, VariableType::kInteger);
  EXPECT_EQ(description->Find("n")->start, 3.0);
  EXPECT_EQ(description->Find("on")->start, 1.0);
  EXPECT_EQ(description->Find("nothing"), nullptr);
  // States in the order of <Derivatives>, which need not be the file's.
  EXPECT_EQ(description->derivative_indices, (std::vector<int>{3, 2}));
  EXPECT_EQ(description->state_indices, (std::vector<int>{1, 0}));
}

TEST(ModelDescription, RefusesAnotherVersionNamingTheOnesRead) {
  const std::string xml = "<fmiModelDescription fmiVersion=\"1.0\" modelName=\"m\"/>";
  auto description = ParseModelDescription(xml, "md.xml");
  ASSERT_FALSE(description.ok());
  EXPECT_THAT(description.status().message(), HasSubstr("md.xml:1: <fmiModelDescription>"));
  EXPECT_THAT(description.status().message(),
              HasSubstr("attribute fmiVersion: expected \"2.0\" or \"3.0\", got \"1.0\""));
}

TEST(ModelDescription, BadValueReferenceNamesFileLineVariableAndAttribute) {
  const std::string xml = Description("", R"xml(<ModelExchange modelIdentifier="m"/>
<ModelVariables>
  <ScalarVariable name="k" valueReference="seven"><Real/></ScalarVariable>
</ModelVariables>)xml");
  auto description = ParseModelDescription(xml, "md.xml");
  ASSERT_FALSE(description.ok());
  EXPECT_THAT(description.status().message(),
              HasSubstr("md.xml:5: <ScalarVariable name=\"k\">: attribute valueReference: expected an integer >= 0, "
                        "got \"seven\""));
}

TEST(ModelDescription, RefusesAModelIdentifierThatIsAPath) {
  const std::string xml = Description("", R"xml(<CoSimulation modelIdentifier="../../lib/evil"/>
<ModelVariables/>)xml");
  auto description = ParseModelDescription(xml, "md.xml");
  ASSERT_FALSE(description.ok());
  EXPECT_THAT(description.status().message(), HasSubstr("<CoSimulation>: attribute modelIdentifier: expected a C identifier"));
}

TEST(ModelDescription, RefusesADescriptionWithoutInterfaceOrVariables) {
  auto no_interface = ParseModelDescription(Description("", "<ModelVariables/>"), "md.xml");
  ASSERT_FALSE(no_interface.ok());
  EXPECT_THAT(no_interface.status().message(), HasSubstr("expected a <ModelExchange> or <CoSimulation> element"));
  auto no_variables = ParseModelDescription(Description("", "<ModelExchange modelIdentifier=\"m\"/>"), "md.xml");
  ASSERT_FALSE(no_variables.ok());
  EXPECT_THAT(no_variables.status().message(), HasSubstr("expected a <ModelVariables> element, got none"));
}

TEST(ModelDescription, RefusesADerivativeUnknownThatIsNoDerivative) {
  const std::string xml = Description("", R"xml(<ModelExchange modelIdentifier="m"/>
<ModelVariables>
  <ScalarVariable name="x" valueReference="0"><Real/></ScalarVariable>
</ModelVariables>
<ModelStructure><Derivatives><Unknown index="1"/></Derivatives></ModelStructure>)xml");
  auto description = ParseModelDescription(xml, "md.xml");
  ASSERT_FALSE(description.ok());
  EXPECT_THAT(description.status().message(), HasSubstr("md.xml:7: <Unknown>: attribute index: variable 1 (\"x\") is not"));
}

TEST(ModelDescription, NotWellFormedXmlNamesTheLine) {
  auto description = ParseModelDescription("<fmiModelDescription fmiVersion=\"2.0\">\n<ModelVariables>\n</Model", "md.xml");
  ASSERT_FALSE(description.ok());
  EXPECT_THAT(description.status().message(), HasSubstr("md.xml:3: not well-formed XML"));
}

TEST(ModelDescription, RefusesTwoVariablesOfOneName) {
  const std::string xml = Description("", R"xml(<ModelExchange modelIdentifier="m"/>
<ModelVariables>
  <ScalarVariable name="x" valueReference="0"><Real/></ScalarVariable>
  <ScalarVariable name="x" valueReference="1"><Real/></ScalarVariable>
</ModelVariables>)xml");
  auto description = ParseModelDescription(xml, "md.xml");
  ASSERT_FALSE(description.ok());
  EXPECT_THAT(description.status().message(), HasSubstr("md.xml:6: <ScalarVariable name=\"x\">: attribute name: a second"));
}

}  // namespace
}  // namespace mbopt::fmu
