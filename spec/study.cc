#include "spec/study.h"

#include "common/check.h"

namespace mbopt::spec {

std::vector<double> Study::ParameterValuesAt(const std::vector<double>& x_scaled) const {
  MBOPT_CHECK(x_scaled.size() == variables.size(), "design vector size != number of variables");
  std::vector<double> values = scene.DefaultParameterValues();
  for (size_t k = 0; k < variables.size(); ++k) {
    const DesignVariable& v = variables[k];
    const Parameter& p = scene.parameters[static_cast<size_t>(v.parameter)];
    const double si = v.scale * x_scaled[k] * p.si_per_unit;
    values[static_cast<size_t>(v.parameter)] = si;
    for (int also : v.also_sets) values[static_cast<size_t>(also)] = si;
  }
  return values;
}

std::vector<double> Study::CaseParameterValues(int c, std::vector<double> parameter_values_si) const {
  if (cases.empty()) return parameter_values_si;
  for (const auto& [parameter, value] : cases[static_cast<size_t>(c)].parameter_values_si) {
    parameter_values_si[static_cast<size_t>(parameter)] = value;
  }
  return parameter_values_si;
}

std::string Study::SignalName(int signal) const {
  MBOPT_CHECK(signal >= 0 && signal < num_signals(), "signal index out of range");
  if (signal >= num_case_signals()) return responses[static_cast<size_t>(signal - num_case_signals())].name;
  const size_t outputs = scene.outputs.size();
  const std::string& output = scene.outputs[static_cast<size_t>(signal) % outputs].name;
  if (cases.empty()) return output;
  return cases[static_cast<size_t>(signal) / outputs].name + "." + output;
}

int Study::FindSignal(const std::string& name) const {
  for (int s = 0; s < num_signals(); ++s) {
    if (SignalName(s) == name) return s;
  }
  return -1;
}

}  // namespace mbopt::spec
