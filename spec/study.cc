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

}  // namespace mbopt::spec
