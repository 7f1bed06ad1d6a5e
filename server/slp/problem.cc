#include "server/slp/problem.h"

#include <cmath>

#include "absl/strings/str_cat.h"

namespace mbopt::slp {
namespace {

std::string VariableLabel(const ProblemSpec& spec, int i) {
  if (i < static_cast<int>(spec.variable_names.size()) && !spec.variable_names[i].empty()) {
    return absl::StrCat("variable ", i, " '", spec.variable_names[i], "'");
  }
  return absl::StrCat("variable ", i);
}

std::string ConstraintLabel(const ProblemSpec& spec, int h) {
  if (h < static_cast<int>(spec.constraint_names.size()) && !spec.constraint_names[h].empty()) {
    return absl::StrCat("constraint ", h, " '", spec.constraint_names[h], "'");
  }
  return absl::StrCat("constraint ", h);
}

}  // namespace

absl::Status ProblemSpec::Validate() const {
  const int n = num_variables();
  if (n < 1) return absl::InvalidArgumentError("ProblemSpec: no design variables");
  if (upper.size() != n || initial.size() != n) {
    return absl::InvalidArgumentError(absl::StrCat(
        "ProblemSpec: lower, upper and initial must have one entry per variable; sizes ", n,
        ", ", upper.size(), ", ", initial.size()));
  }
  if (static_cast<int>(variable_names.size()) != n) {
    return absl::InvalidArgumentError(absl::StrCat("ProblemSpec: ", variable_names.size(),
                                                   " variable names for ", n, " variables"));
  }
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(lower[i]) || !std::isfinite(upper[i]) || !(lower[i] < upper[i])) {
      return absl::InvalidArgumentError(absl::StrCat(
          "ProblemSpec: ", VariableLabel(*this, i), " needs finite bounds lower < upper; got [",
          lower[i], ", ", upper[i], "]"));
    }
    if (!std::isfinite(initial[i]) || initial[i] < lower[i] || initial[i] > upper[i]) {
      return absl::InvalidArgumentError(absl::StrCat(
          "ProblemSpec: ", VariableLabel(*this, i), " initial value ", initial[i],
          " is outside its bounds [", lower[i], ", ", upper[i], "]"));
    }
  }
  if (objective_form == ObjectiveForm::kScalar && num_objective_terms != 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "ProblemSpec: a scalar objective has exactly 1 term; got num_objective_terms = ",
        num_objective_terms));
  }
  if (num_objective_terms < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "ProblemSpec: num_objective_terms = ", num_objective_terms, " must be >= 1"));
  }
  if (objective_form == ObjectiveForm::kSumOfMax) {
    long long total = 0;
    for (int size : objective_group_sizes) {
      if (size < 1) {
        return absl::InvalidArgumentError(
            absl::StrCat("ProblemSpec: an objective group has ", size, " terms; each needs at least 1"));
      }
      total += size;
    }
    if (objective_group_sizes.empty() || total != num_objective_terms) {
      return absl::InvalidArgumentError(absl::StrCat("ProblemSpec: the objective groups hold ", total,
                                                     " terms; num_objective_terms = ", num_objective_terms));
    }
  } else if (!objective_group_sizes.empty()) {
    return absl::InvalidArgumentError("ProblemSpec: objective groups belong to the sum-of-maxima form only");
  }
  const int m = num_constraints();
  if (static_cast<int>(constraint_names.size()) != m || constraint_scales.size() != m) {
    return absl::InvalidArgumentError(absl::StrCat(
        "ProblemSpec: constraint_limits, constraint_names and constraint_scales must have one "
        "entry per constraint row; sizes ",
        m, ", ", constraint_names.size(), ", ", constraint_scales.size()));
  }
  for (int h = 0; h < m; ++h) {
    if (!std::isfinite(constraint_limits[h])) {
      return absl::InvalidArgumentError(absl::StrCat("ProblemSpec: ", ConstraintLabel(*this, h),
                                                     " limit is not finite: ",
                                                     constraint_limits[h]));
    }
    if (!std::isfinite(constraint_scales[h]) || constraint_scales[h] <= 0.0) {
      return absl::InvalidArgumentError(
          absl::StrCat("ProblemSpec: ", ConstraintLabel(*this, h),
                       " scale must be finite and > 0; got ", constraint_scales[h]));
    }
  }
  return absl::OkStatus();
}

std::vector<ObjectiveGroup> ProblemSpec::ObjectiveGroups() const {
  if (objective_form != ObjectiveForm::kSumOfMax) return {ObjectiveGroup{0, num_objective_terms}};
  std::vector<ObjectiveGroup> groups;
  groups.reserve(objective_group_sizes.size());
  int first = 0;
  for (int size : objective_group_sizes) {
    groups.push_back(ObjectiveGroup{first, size});
    first += size;
  }
  return groups;
}

double ObjectiveValue(const ProblemSpec& spec, const Eigen::VectorXd& terms) {
  if (spec.objective_form != ObjectiveForm::kSumOfMax) return terms.maxCoeff();
  double sum = 0;
  for (const ObjectiveGroup& g : spec.ObjectiveGroups()) sum += terms.segment(g.first, g.size).maxCoeff();
  return sum;
}

}  // namespace mbopt::slp
