// Reading the attributes of a modelDescription.xml, shared by the FMI 2.0
// (model_description.cc) and FMI 3.0 (fmi3_model_description.cc) parsers:
// every error names the file, the line, the element and the attribute, and
// what was expected. Internal to worker/fmu.
#pragma once

#include <pugixml.hpp>

#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "worker/fmu/model_description.h"

namespace mbopt::fmu::internal {

// Where an element is, for errors: "file:line: <Element name=\"...\">".
class Locator {
 public:
  Locator(std::string_view text, std::string_view file_label) : text_(text), file_label_(file_label) {}

  const std::string& file_label() const { return file_label_; }
  std::string Where(const pugi::xml_node& node) const;
  absl::Status Error(const pugi::xml_node& node, const std::string& what) const;

 private:
  std::string_view text_;
  std::string file_label_;
};

absl::StatusOr<double> ParseDouble(const Locator& at, const pugi::xml_node& node, const char* attribute);
// An unsigned integer of at most 32 bits, at least `min_value`.
absl::StatusOr<long> ParseInteger(const Locator& at, const pugi::xml_node& node, const char* attribute,
                                  long min_value);
// An absent attribute is false.
absl::StatusOr<bool> ParseBoolean(const Locator& at, const pugi::xml_node& node, const char* attribute);
absl::StatusOr<Causality> ParseCausality(const Locator& at, const pugi::xml_node& node);
absl::StatusOr<Variability> ParseVariability(const Locator& at, const pugi::xml_node& node);
// <ModelExchange> or <CoSimulation>; the versions spell the directional
// derivative flag differently (providesDirectionalDerivative in 2.0,
// providesDirectionalDerivatives in 3.0).
absl::StatusOr<InterfaceType> ParseInterfaceType(const Locator& at, const pugi::xml_node& node,
                                                 const char* directional_derivative_attribute);
// Both interface blocks of `root` that are present, into `out`.
absl::Status ParseInterfaceTypes(const Locator& at, const pugi::xml_node& root,
                                 const char* directional_derivative_attribute, ModelDescription* out);
absl::Status ParseDefaultExperiment(const Locator& at, const pugi::xml_node& node, DefaultExperiment* out);

// The FMI 3.0 part of ParseModelDescription, from the root element on.
absl::StatusOr<ModelDescription> ParseFmi3ModelDescription(const Locator& at, const pugi::xml_node& root);

}  // namespace mbopt::fmu::internal
