// The parts of an FMI 2.0 or 3.0 modelDescription.xml that mbopt uses to
// run an FMU: its identity, which interface types it offers, its scalar
// variables and its default experiment. Parsed from text (the archive reader passes
// the file's contents), so the parser is tested without an archive.
//
// Errors are InvalidArgument naming the file (as the caller labels it), the
// element and the attribute, and what was expected.
//
// FMI 3.0: the variables' types are elements of their own (<Float64>,
// <Int32>, ...); mbopt reads Float64 scalars. Refused with the variable or
// element named: clocks (<Clock> variables, or variables with `clocks`),
// arrays (<Dimension>, structural parameters), parameters, inputs and
// outputs of any type but Float64, and Scheduled Execution.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"

namespace mbopt::fmu {

enum class Causality { kParameter, kCalculatedParameter, kInput, kOutput, kLocal, kIndependent };
enum class Variability { kConstant, kFixed, kTunable, kDiscrete, kContinuous };
// kReal: FMI 2.0 Real or FMI 3.0 Float64 (what fmi2GetReal / fmi3GetFloat64
// read). kOther: FMI 3.0 types mbopt does not read (Float32, Binary), only
// allowed for local variables.
enum class VariableType { kReal, kInteger, kBoolean, kString, kEnumeration, kOther };

struct ScalarVariable {
  std::string name;
  unsigned int value_reference = 0;
  Causality causality = Causality::kLocal;
  Variability variability = Variability::kContinuous;
  VariableType type = VariableType::kReal;
  std::optional<double> start;  // Real, Integer, Boolean and Enumeration starts as numbers
};

// One interface type (<ModelExchange> or <CoSimulation>) the FMU offers.
struct InterfaceType {
  std::string model_identifier;  // the binary's base name
  bool provides_directional_derivative = false;
  bool can_handle_variable_communication_step_size = false;  // co-simulation only
  // The binary keeps an instance's state in its globals: two instances need
  // two copies of the library in the process (fmu.cc).
  bool instantiated_once_per_process = false;
};

struct DefaultExperiment {
  std::optional<double> start_time_s;
  std::optional<double> stop_time_s;
  std::optional<double> tolerance;
  std::optional<double> step_size_s;
};

struct ModelDescription {
  std::string fmi_version;  // "2.0", or "3.0" and its revisions
  int fmi_major_version = 2;
  std::string model_name;
  std::string guid;  // FMI 3.0's instantiationToken
  std::optional<InterfaceType> model_exchange;
  std::optional<InterfaceType> co_simulation;
  int number_of_event_indicators = 0;  // 3.0: the <EventIndicator>s of <ModelStructure>
  std::vector<ScalarVariable> variables;  // in file order; index i is the file's index i + 1
  // Indices into `variables` of the continuous states (in the order of
  // fmi2/fmi3GetContinuousStates) and of their derivatives, from <ModelStructure>.
  std::vector<int> state_indices;
  std::vector<int> derivative_indices;
  DefaultExperiment default_experiment;

  // The variable named `name`, or nullptr.
  const ScalarVariable* Find(std::string_view name) const;
};

const char* CausalityName(Causality causality);

// Parses the text of a modelDescription.xml; `file_label` names it in errors.
absl::StatusOr<ModelDescription> ParseModelDescription(std::string_view xml_text, std::string_view file_label);

}  // namespace mbopt::fmu
