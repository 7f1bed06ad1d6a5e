#include "worker/fmu/model_description.h"

#include <pugixml.hpp>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <string>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace mbopt::fmu {
namespace {

// Where an element is, for errors: "file:line: <Element name=\"...\">".
class Locator {
 public:
  Locator(std::string_view text, std::string_view file_label) : text_(text), file_label_(file_label) {}

  const std::string& file_label() const { return file_label_; }

  std::string Where(const pugi::xml_node& node) const {
    const std::ptrdiff_t offset = std::clamp<std::ptrdiff_t>(node.offset_debug(), 0, text_.size());
    const auto line = 1 + std::count(text_.begin(), text_.begin() + offset, '\n');
    std::string element = absl::StrCat("<", node.name());
    if (const pugi::xml_attribute name = node.attribute("name"); name) {
      absl::StrAppend(&element, " name=\"", name.value(), "\"");
    }
    return absl::StrCat(file_label_, ":", line, ": ", element, ">");
  }

  absl::Status Error(const pugi::xml_node& node, const std::string& what) const {
    return absl::InvalidArgumentError(absl::StrCat(Where(node), ": ", what));
  }

 private:
  std::string_view text_;
  std::string file_label_;
};

absl::StatusOr<double> ParseDouble(const Locator& at, const pugi::xml_node& node, const char* attribute) {
  const std::string text = node.attribute(attribute).value();
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE) {
    return at.Error(node, absl::StrCat("attribute ", attribute, ": expected a number, got \"", text, "\""));
  }
  return value;
}

absl::StatusOr<long> ParseInteger(const Locator& at, const pugi::xml_node& node, const char* attribute,
                                  long min_value) {
  const std::string text = node.attribute(attribute).value();
  errno = 0;
  char* end = nullptr;
  const long value = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || value < min_value ||
      value > 0xFFFFFFFFL) {
    return at.Error(node, absl::StrCat("attribute ", attribute, ": expected an integer >= ", min_value,
                                       ", got \"", text, "\""));
  }
  return value;
}

absl::StatusOr<bool> ParseBoolean(const Locator& at, const pugi::xml_node& node, const char* attribute) {
  const pugi::xml_attribute value = node.attribute(attribute);
  if (!value) return false;
  const std::string text = value.value();
  if (text == "true") return true;
  if (text == "false") return false;
  return at.Error(node, absl::StrCat("attribute ", attribute, ": expected true or false, got \"", text, "\""));
}

absl::StatusOr<Causality> ParseCausality(const Locator& at, const pugi::xml_node& node) {
  const pugi::xml_attribute value = node.attribute("causality");
  const std::string text = value ? value.value() : "local";
  if (text == "parameter") return Causality::kParameter;
  if (text == "calculatedParameter") return Causality::kCalculatedParameter;
  if (text == "input") return Causality::kInput;
  if (text == "output") return Causality::kOutput;
  if (text == "local") return Causality::kLocal;
  if (text == "independent") return Causality::kIndependent;
  return at.Error(node, absl::StrCat("attribute causality: expected parameter, calculatedParameter, input, "
                                     "output, local or independent, got \"", text, "\""));
}

absl::StatusOr<Variability> ParseVariability(const Locator& at, const pugi::xml_node& node) {
  const pugi::xml_attribute value = node.attribute("variability");
  const std::string text = value ? value.value() : "continuous";
  if (text == "constant") return Variability::kConstant;
  if (text == "fixed") return Variability::kFixed;
  if (text == "tunable") return Variability::kTunable;
  if (text == "discrete") return Variability::kDiscrete;
  if (text == "continuous") return Variability::kContinuous;
  return at.Error(node, absl::StrCat("attribute variability: expected constant, fixed, tunable, discrete or "
                                     "continuous, got \"", text, "\""));
}

absl::StatusOr<InterfaceType> ParseInterfaceType(const Locator& at, const pugi::xml_node& node) {
  InterfaceType type;
  type.model_identifier = node.attribute("modelIdentifier").value();
  if (type.model_identifier.empty()) {
    return at.Error(node, "attribute modelIdentifier: expected the binary's name, got nothing");
  }
  // The identifier becomes a file name: a path in it could name any library.
  if (type.model_identifier.find_first_of("/\\") != std::string::npos || type.model_identifier[0] == '.') {
    return at.Error(node, absl::StrCat("attribute modelIdentifier: expected a C identifier, got \"",
                                       type.model_identifier, "\""));
  }
  auto derivative = ParseBoolean(at, node, "providesDirectionalDerivative");
  if (!derivative.ok()) return derivative.status();
  type.provides_directional_derivative = *derivative;
  auto variable_step = ParseBoolean(at, node, "canHandleVariableCommunicationStepSize");
  if (!variable_step.ok()) return variable_step.status();
  type.can_handle_variable_communication_step_size = *variable_step;
  return type;
}

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

absl::Status ParseDefaultExperiment(const Locator& at, const pugi::xml_node& node, DefaultExperiment* out) {
  const std::pair<const char*, std::optional<double>*> fields[] = {
      {"startTime", &out->start_time_s},
      {"stopTime", &out->stop_time_s},
      {"tolerance", &out->tolerance},
      {"stepSize", &out->step_size_s},
  };
  for (const auto& [attribute, field] : fields) {
    if (!node.attribute(attribute)) continue;
    auto value = ParseDouble(at, node, attribute);
    if (!value.ok()) return value.status();
    *field = *value;
  }
  if (out->step_size_s.has_value() && !(*out->step_size_s > 0.0)) {
    return at.Error(node, absl::StrCat("attribute stepSize: expected a step > 0 s, got ", *out->step_size_s));
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
  if (description.fmi_version.rfind("3.", 0) == 0) {
    return at.Error(root, absl::StrCat("attribute fmiVersion: this is an FMI ", description.fmi_version,
                                       " FMU; mbopt runs FMI 2.0 FMUs only"));
  }
  if (description.fmi_version != "2.0") {
    return at.Error(root, absl::StrCat("attribute fmiVersion: expected \"2.0\", got \"", description.fmi_version,
                                       "\""));
  }
  description.model_name = root.attribute("modelName").value();
  description.guid = root.attribute("guid").value();
  if (root.attribute("numberOfEventIndicators")) {
    auto count = ParseInteger(at, root, "numberOfEventIndicators", 0);
    if (!count.ok()) return count.status();
    description.number_of_event_indicators = static_cast<int>(*count);
  }
  if (const pugi::xml_node node = root.child("ModelExchange"); node) {
    auto type = ParseInterfaceType(at, node);
    if (!type.ok()) return type.status();
    description.model_exchange = *std::move(type);
  }
  if (const pugi::xml_node node = root.child("CoSimulation"); node) {
    auto type = ParseInterfaceType(at, node);
    if (!type.ok()) return type.status();
    description.co_simulation = *std::move(type);
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
