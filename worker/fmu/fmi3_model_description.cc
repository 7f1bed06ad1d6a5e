// The FMI 3.0 model description (see model_description.h for what is read
// and what is refused). Unlike 2.0, a variable's type is its element's name,
// a derivative names its state by value reference, and <ModelStructure>
// lists derivatives and event indicators by value reference.
#include <map>
#include <string>

#include "absl/strings/str_cat.h"
#include "worker/fmu/model_description_xml.h"

namespace mbopt::fmu::internal {
namespace {

enum class Fmi3Type { kFloat64, kFloat32, kInteger, kBoolean, kString, kBinary, kEnumeration, kClock, kUnknown };

Fmi3Type TypeOf(const std::string& element) {
  if (element == "Float64") return Fmi3Type::kFloat64;
  if (element == "Float32") return Fmi3Type::kFloat32;
  if (element == "Int8" || element == "UInt8" || element == "Int16" || element == "UInt16" || element == "Int32" ||
      element == "UInt32" || element == "Int64" || element == "UInt64") {
    return Fmi3Type::kInteger;
  }
  if (element == "Boolean") return Fmi3Type::kBoolean;
  if (element == "String") return Fmi3Type::kString;
  if (element == "Binary") return Fmi3Type::kBinary;
  if (element == "Enumeration") return Fmi3Type::kEnumeration;
  if (element == "Clock") return Fmi3Type::kClock;
  return Fmi3Type::kUnknown;
}

VariableType VariableTypeOf(Fmi3Type type) {
  switch (type) {
    case Fmi3Type::kFloat64: return VariableType::kReal;
    case Fmi3Type::kInteger: return VariableType::kInteger;
    case Fmi3Type::kBoolean: return VariableType::kBoolean;
    case Fmi3Type::kString: return VariableType::kString;
    case Fmi3Type::kEnumeration: return VariableType::kEnumeration;
    default: return VariableType::kOther;
  }
}

// One variable element; `state_reference` is its `derivative` attribute (the
// value reference of the state it is the derivative of), or -1.
absl::Status ParseVariable(const Locator& at, const pugi::xml_node& node, ScalarVariable* variable,
                           long* state_reference) {
  const std::string element = node.name();
  const Fmi3Type type = TypeOf(element);
  variable->name = node.attribute("name").value();
  if (type == Fmi3Type::kUnknown) {
    return at.Error(node, "expected a variable element (<Float64>, <Int32>, <Boolean>, ...)");
  }
  if (variable->name.empty()) return at.Error(node, "attribute name: expected a variable name, got nothing");
  if (type == Fmi3Type::kClock) {
    return at.Error(node, "clocks are not supported: mbopt runs FMI 3.0 FMUs without clocks");
  }
  if (node.attribute("clocks")) {
    return at.Error(node, "attribute clocks: clocked variables are not supported: mbopt runs FMI 3.0 FMUs "
                          "without clocks");
  }
  if (node.child("Dimension")) {
    return at.Error(node, "<Dimension>: array variables are not supported: mbopt reads scalar variables only");
  }
  const std::string causality = node.attribute("causality").value();
  if (causality == "structuralParameter") {
    return at.Error(node, "attribute causality: structural parameters (array sizes) are not supported");
  }
  auto reference = ParseInteger(at, node, "valueReference", 0);
  if (!reference.ok()) return reference.status();
  variable->value_reference = static_cast<unsigned int>(*reference);
  auto parsed_causality = ParseCausality(at, node);
  if (!parsed_causality.ok()) return parsed_causality.status();
  variable->causality = *parsed_causality;
  auto variability = ParseVariability(at, node);
  if (!variability.ok()) return variability.status();
  variable->variability = *variability;
  variable->type = VariableTypeOf(type);
  if (type != Fmi3Type::kFloat64 && variable->causality != Causality::kLocal &&
      variable->causality != Causality::kIndependent) {
    const std::string causality_name = CausalityName(variable->causality);
    const bool vowel = causality_name[0] == 'i' || causality_name[0] == 'o';
    return at.Error(node, absl::StrCat(vowel ? "an " : "a ", causality_name, " of type ", element,
                                       " is not supported: mbopt sets and reads Float64 variables only"));
  }
  if (node.attribute("start")) {
    if (type == Fmi3Type::kBoolean) {
      auto start = ParseBoolean(at, node, "start");
      if (!start.ok()) return start.status();
      variable->start = *start ? 1.0 : 0.0;
    } else if (type == Fmi3Type::kFloat64 || type == Fmi3Type::kInteger || type == Fmi3Type::kEnumeration) {
      auto start = ParseDouble(at, node, "start");
      if (!start.ok()) return start.status();
      variable->start = *start;
    }
  }
  *state_reference = -1;
  if (type == Fmi3Type::kFloat64 && node.attribute("derivative")) {
    auto state = ParseInteger(at, node, "derivative", 0);
    if (!state.ok()) return state.status();
    *state_reference = *state;
  }
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<ModelDescription> ParseFmi3ModelDescription(const Locator& at, const pugi::xml_node& root) {
  ModelDescription description;
  description.fmi_version = root.attribute("fmiVersion").value();
  description.fmi_major_version = 3;
  description.model_name = root.attribute("modelName").value();
  description.guid = root.attribute("instantiationToken").value();
  if (description.guid.empty()) {
    return at.Error(root, "attribute instantiationToken: expected the FMU's token, got nothing");
  }
  if (absl::Status status = ParseInterfaceTypes(at, root, "providesDirectionalDerivatives", &description); !status.ok()) {
    return status;
  }
  if (!description.model_exchange && !description.co_simulation) {
    if (const pugi::xml_node node = root.child("ScheduledExecution"); node) {
      return at.Error(node, "Scheduled Execution is not supported: mbopt runs FMI 3.0 Model Exchange and "
                            "Co-Simulation, and this FMU offers neither");
    }
    return at.Error(root, "expected a <ModelExchange> or <CoSimulation> element, got neither");
  }
  if (const pugi::xml_node node = root.child("DefaultExperiment"); node) {
    if (absl::Status status = ParseDefaultExperiment(at, node, &description.default_experiment); !status.ok()) {
      return status;
    }
  }

  const pugi::xml_node variables = root.child("ModelVariables");
  if (!variables) return at.Error(root, "expected a <ModelVariables> element, got none");
  std::map<long, int> index_of_reference;
  std::vector<long> state_reference_of;
  for (const pugi::xml_node node : variables.children()) {
    if (node.type() != pugi::node_element) continue;
    ScalarVariable variable;
    long state_reference = -1;
    if (absl::Status status = ParseVariable(at, node, &variable, &state_reference); !status.ok()) return status;
    if (description.Find(variable.name) != nullptr) {
      return at.Error(node, "attribute name: a second variable of this name");
    }
    const int index = static_cast<int>(description.variables.size());
    if (!index_of_reference.emplace(variable.value_reference, index).second) {
      return at.Error(node, absl::StrCat("attribute valueReference: ", variable.value_reference, " is already \"",
                                         description.variables[index_of_reference[variable.value_reference]].name,
                                         "\"'s; FMI 3.0 value references are unique"));
    }
    description.variables.push_back(std::move(variable));
    state_reference_of.push_back(state_reference);
  }

  const auto variable_of = [&](const pugi::xml_node& unknown) -> absl::StatusOr<int> {
    auto reference = ParseInteger(at, unknown, "valueReference", 0);
    if (!reference.ok()) return reference.status();
    const auto found = index_of_reference.find(*reference);
    if (found == index_of_reference.end()) {
      return at.Error(unknown, absl::StrCat("attribute valueReference: no variable has value reference ", *reference));
    }
    return found->second;
  };
  const pugi::xml_node structure = root.child("ModelStructure");
  for (const pugi::xml_node unknown : structure.children("ContinuousStateDerivative")) {
    auto derivative = variable_of(unknown);
    if (!derivative.ok()) return derivative.status();
    const long state_reference = state_reference_of[*derivative];
    const auto state = index_of_reference.find(state_reference);
    if (state_reference < 0 || state == index_of_reference.end() ||
        description.variables[state->second].type != VariableType::kReal) {
      return at.Error(unknown, absl::StrCat("attribute valueReference: variable \"",
                                            description.variables[*derivative].name,
                                            "\" is not a <Float64 derivative=\"...\"> of a Float64 variable"));
    }
    description.derivative_indices.push_back(*derivative);
    description.state_indices.push_back(state->second);
  }
  for (const pugi::xml_node unknown : structure.children("EventIndicator")) {
    auto indicator = variable_of(unknown);
    if (!indicator.ok()) return indicator.status();
    ++description.number_of_event_indicators;
  }
  return description;
}

}  // namespace mbopt::fmu::internal
