#include "worker/fmu/model_description_xml.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <optional>
#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace mbopt::fmu::internal {

std::string Locator::Where(const pugi::xml_node& node) const {
  const std::ptrdiff_t offset = std::clamp<std::ptrdiff_t>(node.offset_debug(), 0, text_.size());
  const auto line = 1 + std::count(text_.begin(), text_.begin() + offset, '\n');
  std::string element = absl::StrCat("<", node.name());
  if (const pugi::xml_attribute name = node.attribute("name"); name) {
    absl::StrAppend(&element, " name=\"", name.value(), "\"");
  }
  return absl::StrCat(file_label_, ":", line, ": ", element, ">");
}

absl::Status Locator::Error(const pugi::xml_node& node, const std::string& what) const {
  return absl::InvalidArgumentError(absl::StrCat(Where(node), ": ", what));
}

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

absl::StatusOr<InterfaceType> ParseInterfaceType(const Locator& at, const pugi::xml_node& node,
                                                 const char* directional_derivative_attribute) {
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
  auto derivative = ParseBoolean(at, node, directional_derivative_attribute);
  if (!derivative.ok()) return derivative.status();
  type.provides_directional_derivative = *derivative;
  auto variable_step = ParseBoolean(at, node, "canHandleVariableCommunicationStepSize");
  if (!variable_step.ok()) return variable_step.status();
  type.can_handle_variable_communication_step_size = *variable_step;
  auto once = ParseBoolean(at, node, "canBeInstantiatedOnlyOncePerProcess");
  if (!once.ok()) return once.status();
  type.instantiated_once_per_process = *once;
  return type;
}

absl::Status ParseInterfaceTypes(const Locator& at, const pugi::xml_node& root,
                                 const char* directional_derivative_attribute, ModelDescription* out) {
  const std::pair<const char*, std::optional<InterfaceType>*> blocks[] = {
      {"ModelExchange", &out->model_exchange},
      {"CoSimulation", &out->co_simulation},
  };
  for (const auto& [element, slot] : blocks) {
    const pugi::xml_node node = root.child(element);
    if (!node) continue;
    absl::StatusOr<InterfaceType> type = ParseInterfaceType(at, node, directional_derivative_attribute);
    if (!type.ok()) return type.status();
    *slot = *std::move(type);
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

}  // namespace mbopt::fmu::internal
