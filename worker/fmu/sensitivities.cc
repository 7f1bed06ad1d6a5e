#include "worker/fmu/sensitivities.h"

#include <memory>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "worker/fmu/run_steps.h"

namespace mbopt::fmu {

std::string SensitivitiesUnavailable(const Fmu& fmu, const std::vector<std::string>& parameter_names) {
  const ModelDescription& description = fmu.description();
  const bool fmi3 = description.fmi_major_version >= 3;
  const std::string where = fmu.archive_path().string();
  if (fmu.interface() != Interface::kModelExchange) {
    return absl::StrCat(where, ": a Co-Simulation FMU integrates itself, so it has no forward sensitivities "
                               "(use its Model Exchange interface)");
  }
  if (!fmu.interface_type().provides_directional_derivative) {
    return absl::StrCat(where, ": the FMU does not declare ",
                        fmi3 ? "providesDirectionalDerivatives" : "providesDirectionalDerivative",
                        "=\"true\" on <ModelExchange>");
  }
  if (!fmu.exports_directional_derivative()) {
    return absl::StrCat(where, ": the FMU's binary has no ",
                        fmi3 ? "fmi3GetDirectionalDerivative" : "fmi2GetDirectionalDerivative");
  }
  if (description.number_of_event_indicators > 0) {
    return absl::StrCat(where, ": the FMU has ", description.number_of_event_indicators,
                        " event indicators, and sensitivities across events are not computed");
  }
  for (const std::string& name : parameter_names) {
    const ScalarVariable* variable = description.Find(name);
    if (variable == nullptr || variable->type != VariableType::kReal || variable->causality != Causality::kParameter) {
      return absl::StrCat(where, ": \"", name, "\" is no Real parameter of the FMU");
    }
    if (variable->variability != Variability::kTunable) {
      return absl::StrCat(where, ": FMU parameter \"", name,
                          "\" is not tunable; directional derivatives with respect to a parameter need "
                          "variability=\"tunable\"");
    }
  }
  return "";
}

absl::StatusOr<SensitivityResult> SimulateWithSensitivities(const Fmu& fmu, const RunOptions& options,
                                                            const std::vector<int>& parameters) {
  auto run = internal::CheckRequest(fmu, options);
  if (!run.ok()) return run.status();
  std::vector<std::string> names;
  internal::SensitivityRun sensitivities;
  for (int k : parameters) {
    if (k < 0 || static_cast<std::size_t>(k) >= options.parameters.size()) {
      return absl::InvalidArgumentError(
          absl::StrCat("sensitivity parameter ", k, " is not one of the run's ", options.parameters.size(),
                       " parameters"));
    }
    names.push_back(options.parameters[k].first);
    sensitivities.parameter_references.push_back(run->parameter_references[k]);
  }
  if (std::string why = SensitivitiesUnavailable(fmu, names); !why.empty()) {
    return absl::InvalidArgumentError(why);
  }
  const ModelDescription& description = fmu.description();
  for (std::size_t i = 0; i < description.state_indices.size(); ++i) {
    sensitivities.state_references.push_back(description.variables[description.state_indices[i]].value_reference);
    sensitivities.derivative_references.push_back(
        description.variables[description.derivative_indices[i]].value_reference);
  }
  for (ValueReference output : run->output_references) {
    int state = -1;
    for (std::size_t i = 0; i < sensitivities.state_references.size(); ++i) {
      if (sensitivities.state_references[i] == output) state = static_cast<int>(i);
    }
    sensitivities.output_state_index.push_back(state);
  }

  SensitivityResult result;
  std::unique_ptr<ModelInstance> instance = internal::Instantiate(fmu, &result.run);
  if (instance == nullptr) return result;
  result.run = internal::RunModelExchange(fmu, *instance, options, *run, &sensitivities);
  if (result.run.outcome == RunOutcome::kOk && sensitivities.unavailable.empty()) {
    result.output_derivatives = std::move(sensitivities.output_derivatives);
  }
  result.unavailable = std::move(sensitivities.unavailable);
  return result;
}

}  // namespace mbopt::fmu
