// The optimization problem as the SLP core sees it: scaled, dimensionless
// design variables x, an objective that is one value, the maximum of a
// family of terms (min-max), or a sum of such maxima, and one-sided
// constraint rows g_h(x) <= c_h.
// Study files, units and time grids are resolved before this point
// (spec/layout.h); the core never sees a physical unit.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/status.h"

namespace mbopt::slp {

enum class ObjectiveForm {
  kScalar,  // F(x) = f_0(x): exactly one objective term
  kMinMax,  // F(x) = max_i f_i(x): handled with the bound variable beta
  // F(x) = sum_g max_{i in group g} f_i(x): one bound variable per group.
  // A weighted sum of peaks (positive weights folded into the terms); a
  // group of one term is an ordinary smooth summand.
  kSumOfMax,
};

// The consecutive objective terms [first, first + size) whose maximum is one
// summand of F.
struct ObjectiveGroup {
  int first = 0;
  int size = 1;
};

struct ProblemSpec {
  std::vector<std::string> variable_names;  // n
  Eigen::VectorXd lower;    // n, scaled
  Eigen::VectorXd upper;    // n, scaled
  Eigen::VectorXd initial;  // n, scaled; lower <= initial <= upper
  ObjectiveForm objective_form = ObjectiveForm::kScalar;
  int num_objective_terms = 1;  // 1 for kScalar
  // kSumOfMax only: the sizes of the groups, in term order, summing to
  // num_objective_terms.
  std::vector<int> objective_group_sizes;
  std::vector<std::string> constraint_names;  // m, one per row
  Eigen::VectorXd constraint_limits;  // m: c_h in g_h(x) <= c_h
  // m, > 0: the normalized constraint value is (g_h - c_h) / scale_h. The
  // study layer sets scale_h = |c_h| when c_h != 0 (METHOD.md's g/c - 1).
  Eigen::VectorXd constraint_scales;

  int num_variables() const { return static_cast<int>(lower.size()); }
  int num_constraints() const { return static_cast<int>(constraint_limits.size()); }
  absl::Status Validate() const;

  // The groups of terms whose maxima add up to F: one group of one term for
  // kScalar, one of all terms for kMinMax.
  std::vector<ObjectiveGroup> ObjectiveGroups() const;
  // Whether the cycle LP carries bound variables (kMinMax, kSumOfMax).
  bool HasBoundVariables() const { return objective_form != ObjectiveForm::kScalar; }
};

// F at the given term values: the sum over the groups of their largest term.
double ObjectiveValue(const ProblemSpec& spec, const Eigen::VectorXd& terms);

}  // namespace mbopt::slp
