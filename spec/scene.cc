#include "spec/scene.h"

namespace mbopt::spec {

std::vector<double> TimeGrid::Instants() const {
  std::vector<double> instants;
  if (points <= 1) {
    instants.push_back(end_s);
    return instants;
  }
  instants.reserve(static_cast<size_t>(points));
  const double step = (end_s - start_s) / static_cast<double>(points - 1);
  for (int i = 0; i < points; ++i) instants.push_back(start_s + step * i);
  // The last instant is end_s exactly, not start + (n-1) * step rounded.
  instants.back() = end_s;
  return instants;
}

int Scene::FindParameter(const std::string& name) const {
  for (size_t i = 0; i < parameters.size(); ++i) {
    if (parameters[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

int Scene::FindOutput(const std::string& name) const {
  for (size_t i = 0; i < outputs.size(); ++i) {
    if (outputs[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

std::vector<double> Scene::DefaultParameterValues() const {
  std::vector<double> values;
  values.reserve(parameters.size());
  for (const Parameter& p : parameters) values.push_back(p.value_si);
  return values;
}

}  // namespace mbopt::spec
