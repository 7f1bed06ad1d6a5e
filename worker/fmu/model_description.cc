#include "worker/fmu/model_description.h"

#include "worker/fmu/model_description_xml.h"

#include <pugixml.hpp>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace mbopt::fmu {
namespace {

using internal::Locator;
using internal::ParseBoolean;
using internal::ParseDouble;
using internal::ParseInteger;
using internal::ParseCausality;
using internal::ParseVariability;
using internal::ParseInterfaceType;
using internal::ParseDefaultExperiment;

absl::Status ParseScalarVariable(const Locator& at, const pugi::xml_node& node, ScalarVariable* variable,
                                 long* derivative_of) {
  variable->name = node.attribute("name").value();
  if (variable->name.empty()) return at.Error(node, "attribute name: expected a variable name, got nothing");
  auto reference = ParseInteger(at, node, "valueReference", 0);
  if (!reference.ok()) return reference.status();
  variable->value_reference = static_cast<unsigned int>(*reference);
  auto causality = ParseCausality(at, node);
  if (!causality.ok()) return causality.status();
  variable->causality = *causality;
  auto variability = ParseVariability(at, node);
  if (!variability.ok()) return variability.status();
  variable->variability = *variability;

  const pugi::xml_node type = node.first_child();
  const std::string type_name = type ? type.name() : "";
  if (type_name == "Real") {
    variable->type = VariableType::kReal;
  } else if (type_name == "Integer") {
    variable->type = VariableType::kInteger;
  } else if (type_name == "Boolean") {
    variable->type = VariableType::kBoolean;
  } else if (type_name == "String") {
    variable->type = VariableType::kString;
  } else if (type_name == "Enumeration") {
    variable->type = VariableType::kEnumeration;
  } else {
    return at.Error(node, absl::StrCat("expected a <Real>, <Integer>, <Boolean>, <String> or <Enumeration> "
                                       "child, got ", type_name.empty() ? "none" : absl::StrCat("<", type_name, ">")));
  }
  if (type.attribute("start") && variable->type != VariableType::kString) {
    if (variable->type == VariableType::kBoolean) {
      auto start = ParseBoolean(at, type, "start");
      if (!start.ok()) return start.status();
      variable->start = *start ? 1.0 : 0.0;
    } else {
      auto start = ParseDouble(at, type, "start");
      if (!start.ok()) return start.status();
      variable->start = *start;
    }
  }
  *derivative_of = 0;
  if (variable->type == VariableType::kReal && type.attribute("derivative")) {
    auto index = ParseInteger(at, type, "derivative", 1);
    if (!index.ok()) return index.status();
    *derivative_of = *index;
  }
  return absl::OkStatus();
}

}  // namespace

const ScalarVariable* ModelDescription::Find(std::string_view name) const {
  for (const ScalarVariable& variable : variables) {
    if (variable.name == name) return &variable;
  }
  return nullptr;
}

const char* CausalityName(Causality causality) {
  switch (causality) {
    case Causality::kParameter: return "parameter";
    case Causality::kCalculatedParameter: return "calculatedParameter";
    case Causality::kInput: return "input";
    case Causality::kOutput: return "output";
    case Causality::kLocal: return "local";
    case Causality::kIndependent: return "independent";
  }
  return "?";
}

absl::StatusOr<ModelDescription> ParseModelDescription(std::string_view xml_text, std::string_view file_label) {
  pugi::xml_document document;
  const pugi::xml_parse_result parsed = document.load_buffer(xml_text.data(), xml_text.size());
  const Locator at(xml_text, file_label);
  const std::string& label = at.file_label();
  if (!parsed) {
    const std::ptrdiff_t offset = std::clamp<std::ptrdiff_t>(parsed.offset, 0, xml_text.size());
    const auto line = 1 + std::count(xml_text.begin(), xml_text.begin() + offset, '\n');
    return absl::InvalidArgumentError(
        absl::StrCat(label, ":", line, ": not well-formed XML: ", parsed.description()));
  }
  const pugi::xml_node root = document.child("fmiModelDescription");
  if (!root) {
    return absl::InvalidArgumentError(
        absl::StrCat(label, ": expected the root element <fmiModelDescription>, got <",
                     document.first_child().name(), ">"));
  }
  ModelDescription description;
  description.fmi_version = root.attribute("fmiVersion").value();
  // 3.0.x are compatible revisions of 3.0.
  if (description.fmi_version.rfind("3.0", 0) == 0) return internal::ParseFmi3ModelDescription(at, root);
  if (description.fmi_version != "2.0") {
    return at.Error(root, absl::StrCat("attribute fmiVersion: expected \"2.0\" or \"3.0\", got \"",
                                       description.fmi_version, "\""));
  }
  description.model_name = root.attribute("modelName").value();
  description.guid = root.attribute("guid").value();
  if (root.attribute("numberOfEventIndicators")) {
    auto count = ParseInteger(at, root, "numberOfEventIndicators", 0);
    if (!count.ok()) return count.status();
    description.number_of_event_indicators = static_cast<int>(*count);
  }
  if (absl::Status status = ParseInterfaceTypes(at, root, "providesDirectionalDerivative", &description); !status.ok()) {
    return status;
  }
  if (!description.model_exchange && !description.co_simulation) {
    return at.Error(root, "expected a <ModelExchange> or <CoSimulation> element, got neither");
  }
  if (const pugi::xml_node node = root.child("DefaultExperiment"); node) {
    if (absl::Status status = ParseDefaultExperiment(at, node, &description.default_experiment); !status.ok()) {
      return status;
    }
  }

  const pugi::xml_node variables = root.child("ModelVariables");
  if (!variables) return at.Error(root, "expected a <ModelVariables> element, got none");
  std::vector<long> derivative_of;
  for (const pugi::xml_node node : variables.children("ScalarVariable")) {
    ScalarVariable variable;
    long state_index = 0;
    if (absl::Status status = ParseScalarVariable(at, node, &variable, &state_index); !status.ok()) return status;
    if (description.Find(variable.name) != nullptr) {
      return at.Error(node, "attribute name: a second variable of this name");
    }
    description.variables.push_back(std::move(variable));
    derivative_of.push_back(state_index);
  }

  const pugi::xml_node derivatives = root.child("ModelStructure").child("Derivatives");
  for (const pugi::xml_node unknown : derivatives.children("Unknown")) {
    auto index = ParseInteger(at, unknown, "index", 1);
    if (!index.ok()) return index.status();
    const long count = static_cast<long>(description.variables.size());
    if (*index > count) {
      return at.Error(unknown, absl::StrCat("attribute index: expected a variable's index in 1..", count,
                                            ", got ", *index));
    }
    const long state = derivative_of[*index - 1];
    if (state < 1 || state > count) {
      return at.Error(unknown, absl::StrCat("attribute index: variable ", *index, " (\"",
                                            description.variables[*index - 1].name,
                                            "\") is not a <Real derivative=\"...\"> of a variable in 1..", count));
    }
    description.derivative_indices.push_back(static_cast<int>(*index - 1));
    description.state_indices.push_back(static_cast<int>(state - 1));
  }
  return description;
}

}  // namespace mbopt::fmu
