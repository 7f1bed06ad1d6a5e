#include "server/slp/flat_directions.h"

#include <algorithm>
#include <cmath>

namespace mbopt::slp {

std::vector<int> FlatVariables(const ProblemSpec& spec, const SlpOptions& o,
                               const Linearization& lin) {
  std::vector<int> flat;
  const int n = spec.num_variables();
  if (lin.terms0.size() == 0 || lin.x0.size() != n ||
      static_cast<int>(lin.frozen.size()) != n) {
    return flat;
  }
  const double f0 = ObjectiveValue(spec, lin.terms0);
  const double f_scale = std::max(std::abs(f0), o.objective_magnitude_floor);
  const double band = o.convergence_violation_tolerance;
  // The terms that set F: within the band of their group's largest.
  std::vector<bool> sets_objective(static_cast<size_t>(lin.terms0.size()), false);
  for (const ObjectiveGroup& g : spec.ObjectiveGroups()) {
    const double group_max = lin.terms0.segment(g.first, g.size).maxCoeff();
    for (int j = g.first; j < g.first + g.size; ++j) {
      sets_objective[static_cast<size_t>(j)] = (group_max - lin.terms0[j]) / f_scale <= band;
    }
  }
  for (int i = 0; i < n; ++i) {
    if (lin.frozen[i]) continue;
    const double typical = std::max(std::abs(lin.x0[i]), o.move_limit_floor_fraction_of_range *
                                                             (spec.upper[i] - spec.lower[i]));
    double sensitivity = 0;
    for (int j = 0; j < lin.terms0.size(); ++j) {
      if (!sets_objective[static_cast<size_t>(j)]) continue;
      sensitivity = std::max(sensitivity, std::abs(lin.terms_gradient(j, i)) * typical / f_scale);
    }
    for (int h = 0; h < spec.num_constraints(); ++h) {
      const double scale = spec.constraint_scales[h];
      if ((lin.constraints0[h] - spec.constraint_limits[h]) / scale <= -band) continue;
      sensitivity =
          std::max(sensitivity, std::abs(lin.constraints_gradient(h, i)) * typical / scale);
    }
    if (sensitivity <= kFlatRelativeSensitivity) flat.push_back(i);
  }
  return flat;
}

}  // namespace mbopt::slp
