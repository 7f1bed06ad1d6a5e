#include "server/slp/cycle_lp.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/check.h"

namespace mbopt::slp {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// x0 is on a bound within this share of its box half-width (the same
// tolerance as the records' boundact).
constexpr double kBoundActivityRelativeTolerance = 1e-6;

// Largest and smallest change of a linear function grad . d over the box.
double MaxOverBox(const Eigen::VectorXd& grad, const MoveBox& box) {
  double sum = 0;
  for (Eigen::Index i = 0; i < grad.size(); ++i) {
    sum += std::max(grad[i] * box.d_lower[i], grad[i] * box.d_upper[i]);
  }
  return sum;
}
double MinOverBox(const Eigen::VectorXd& grad, const MoveBox& box) {
  double sum = 0;
  for (Eigen::Index i = 0; i < grad.size(); ++i) {
    sum += std::min(grad[i] * box.d_lower[i], grad[i] * box.d_upper[i]);
  }
  return sum;
}

}  // namespace

double PredictedObjective(const ProblemSpec& spec, const Linearization& lin, const Eigen::VectorXd& d,
                          const CycleLp* cycle_lp) {
  const std::vector<ObjectiveGroup> groups = spec.ObjectiveGroups();
  std::vector<double> group_max(groups.size(), -kInf);
  auto offer = [&](int j, int g) {
    group_max[g] = std::max(group_max[g], lin.terms0[j] + lin.terms_gradient.row(j).dot(d));
  };
  if (cycle_lp != nullptr && spec.HasBoundVariables()) {
    for (size_t k = 0; k < cycle_lp->kept_terms.size(); ++k) offer(cycle_lp->kept_terms[k], cycle_lp->kept_term_groups[k]);
  } else {
    for (size_t g = 0; g < groups.size(); ++g) {
      for (int j = groups[g].first; j < groups[g].first + groups[g].size; ++j) offer(j, static_cast<int>(g));
    }
  }
  if (group_max.size() == 1) return group_max[0];
  double sum = 0;
  for (double m : group_max) sum += m;
  return sum;
}

double OptimalityResidual(const ProblemSpec& spec, const SlpOptions& o, const Linearization& lin,
                          const MoveBox& box, const CycleLp& cycle_lp,
                          const lp::LpSolution& solution) {
  if (solution.x[cycle_lp.s_column] > o.infeasibility_tolerance) return kInf;
  const double f0 = ObjectiveValue(spec, lin.terms0);
  const double relative_to = std::max(std::abs(f0), o.objective_magnitude_floor);
  double residual = 0;
  for (int i = 0; i < spec.num_variables(); ++i) {
    if (lin.frozen[i]) continue;
    const double w = box.half_width[i];
    const double d = solution.x[i];
    const double reduced_cost = solution.reduced_costs[i];
    // LP vertices sit on a bound up to the solver's rounding.
    const double slack = 1e-9 * std::max(w, 1e-300);
    const bool at_upper = d >= box.d_upper[i] - slack;
    const bool at_lower = d <= box.d_lower[i] + slack;
    // A design bound holds the gradient back only where x0 is on it: a bound
    // that the box merely reaches is a place the step could go, not a
    // multiplier of the design x0, and counting it would call x0 optimal
    // while it could still move freely away from the bound.
    const double range = spec.upper[i] - spec.lower[i];
    const double on_bound = kBoundActivityRelativeTolerance * std::max(w, 1e-12 * range);
    const bool upper_is_bound = spec.upper[i] - lin.x0[i] <= on_bound;
    const bool lower_is_bound = lin.x0[i] - spec.lower[i] <= on_bound;
    double unbalanced = std::abs(reduced_cost);
    if (at_upper && upper_is_bound) {
      unbalanced = std::max(0.0, reduced_cost);  // a minimum there has reduced cost <= 0
    } else if (at_lower && lower_is_bound) {
      unbalanced = std::max(0.0, -reduced_cost);
    }
    const double typical =
        std::max(std::abs(lin.x0[i]), o.move_limit_floor_fraction_of_range * range);
    residual = std::max(residual, unbalanced * cycle_lp.objective_scale * typical / relative_to);
  }
  // Complementarity at x0: a row that carries a multiplier must be active at
  // x0, not only at x*. A term below its group's largest, or a constraint
  // below its limit, with a multiplier says that the LP's optimum x* lies
  // away from x0 (a vertex of other rows), however small the reduced costs
  // are there.
  double complementarity = 0;
  int row = 0;
  if (cycle_lp.beta_column >= 0) {
    const std::vector<ObjectiveGroup> groups = spec.ObjectiveGroups();
    for (size_t k = 0; k < cycle_lp.kept_terms.size(); ++k) {
      const ObjectiveGroup& g = groups[static_cast<size_t>(cycle_lp.kept_term_groups[k])];
      const double group_max = lin.terms0.segment(g.first, g.size).maxCoeff();
      const double gap = (group_max - lin.terms0[cycle_lp.kept_terms[k]]) / cycle_lp.objective_scale;
      complementarity += std::abs(solution.row_duals[row]) * std::max(0.0, gap);
      ++row;
    }
  }
  for (int h : cycle_lp.kept_constraints) {
    const double slack = (spec.constraint_limits[h] - lin.constraints0[h]) / spec.constraint_scales[h];
    complementarity += std::abs(solution.row_duals[row]) * std::max(0.0, slack);
    ++row;
  }
  return std::max(residual, complementarity * cycle_lp.objective_scale / relative_to);
}

MoveBox ComputeMoveBox(const ProblemSpec& spec, const SlpOptions& o, const Eigen::VectorXd& x0,
                       const Eigen::VectorXd& move_limits, const std::vector<bool>& frozen) {
  const int n = spec.num_variables();
  MoveBox box;
  box.half_width.resize(n);
  box.d_lower.resize(n);
  box.d_upper.resize(n);
  for (int i = 0; i < n; ++i) {
    const double range = spec.upper[i] - spec.lower[i];
    const double w =
        frozen[i] ? 0.0
                  : move_limits[i] * std::max(std::abs(x0[i]),
                                              o.move_limit_floor_fraction_of_range * range);
    box.half_width[i] = w;
    box.d_lower[i] = std::min(0.0, std::max(spec.lower[i] - x0[i], -w));
    box.d_upper[i] = std::max(0.0, std::min(spec.upper[i] - x0[i], w));
  }
  return box;
}

CycleLp BuildCycleLp(const ProblemSpec& spec, const SlpOptions& o, const Linearization& lin,
                     const MoveBox& box) {
  const int n = spec.num_variables();
  const bool bounded = spec.HasBoundVariables();
  const std::vector<ObjectiveGroup> groups = spec.ObjectiveGroups();
  const int num_groups = bounded ? static_cast<int>(groups.size()) : 0;
  const double f0 = ObjectiveValue(spec, lin.terms0);
  CycleLp out;

  // Objective terms, group by group: keep those near the group's maximum and
  // any that could overtake the group's current maximum term inside the box.
  std::vector<double> group_max(groups.size(), 0.0);
  for (int g = 0; g < num_groups; ++g) {
    const ObjectiveGroup& group = groups[static_cast<size_t>(g)];
    Eigen::Index top_in_group = 0;
    group_max[g] = lin.terms0.segment(group.first, group.size).maxCoeff(&top_in_group);
    const int top = group.first + static_cast<int>(top_in_group);
    const double top_floor =
        lin.terms0[top] + MinOverBox(lin.terms_gradient.row(top).transpose(), box);
    const double denom = std::max(std::abs(group_max[g]), o.objective_magnitude_floor);
    for (int j = group.first; j < group.first + group.size; ++j) {
      const double normalized = (lin.terms0[j] - group_max[g]) / denom;
      const double reach =
          lin.terms0[j] + MaxOverBox(lin.terms_gradient.row(j).transpose(), box);
      if (j == top || normalized > o.objective_screening_threshold || reach > top_floor) {
        out.kept_terms.push_back(j);
        out.kept_term_groups.push_back(g);
      }
    }
  }
  if (!bounded) {
    out.kept_terms.push_back(0);
    out.kept_term_groups.push_back(0);
  }
  // Constraints: keep the critical and potentially critical ones, and any
  // whose linearization could reach its limit inside the box.
  for (int h = 0; h < spec.num_constraints(); ++h) {
    const double c = spec.constraint_limits[h];
    const double normalized = (lin.constraints0[h] - c) / spec.constraint_scales[h];
    const double reach =
        lin.constraints0[h] + MaxOverBox(lin.constraints_gradient.row(h).transpose(), box);
    if (normalized > o.screening_threshold || reach > c) out.kept_constraints.push_back(h);
  }

  // How far F can move inside the box: per group, the largest reach of a
  // kept term, summed over the groups.
  std::vector<double> group_spread(groups.size(), 0.0);
  for (size_t k = 0; k < out.kept_terms.size(); ++k) {
    double& spread = group_spread[static_cast<size_t>(out.kept_term_groups[k])];
    spread = std::max(spread, (lin.terms_gradient.row(out.kept_terms[k]).transpose().cwiseAbs().array() *
                               box.half_width.array())
                                  .sum());
  }
  double spread = group_spread[0];
  for (size_t g = 1; g < group_spread.size(); ++g) spread += group_spread[g];
  out.objective_scale = std::max({std::abs(f0), spread, o.objective_magnitude_floor});
  const double scale = out.objective_scale;

  const int columns = n + num_groups + 1;
  out.beta_column = bounded ? n : -1;
  out.s_column = columns - 1;
  const int term_rows = bounded ? static_cast<int>(out.kept_terms.size()) : 0;
  const int rows = term_rows + static_cast<int>(out.kept_constraints.size());

  lp::LinearProgram& lp = out.lp;
  lp.objective = Eigen::VectorXd::Zero(columns);
  lp.column_lower.resize(columns);
  lp.column_upper.resize(columns);
  lp.column_lower.head(n) = box.d_lower;
  lp.column_upper.head(n) = box.d_upper;
  if (bounded) {
    for (int g = 0; g < num_groups; ++g) {
      lp.objective[out.beta_column + g] = 1.0;
      lp.column_lower[out.beta_column + g] = -kInf;
      lp.column_upper[out.beta_column + g] = kInf;
    }
  } else {
    lp.objective.head(n) = lin.terms_gradient.row(0).transpose() / scale;
  }
  lp.objective[out.s_column] = o.infeasibility_penalty;
  lp.column_lower[out.s_column] = 0.0;
  lp.column_upper[out.s_column] = kInf;

  lp.rows = decltype(lp.rows)::Zero(rows, columns);
  lp.row_lower = Eigen::VectorXd::Constant(rows, -kInf);
  lp.row_upper.resize(rows);
  int r = 0;
  for (int k = 0; k < term_rows; ++k, ++r) {
    const int j = out.kept_terms[k];
    const int g = out.kept_term_groups[k];
    lp.rows.row(r).head(n) = lin.terms_gradient.row(j) / scale;
    lp.rows(r, out.beta_column + g) = -1.0;
    lp.row_upper[r] = (group_max[g] - lin.terms0[j]) / scale;
  }
  for (int h : out.kept_constraints) {
    const double sh = spec.constraint_scales[h];
    lp.rows.row(r).head(n) = lin.constraints_gradient.row(h) / sh;
    lp.rows(r, out.s_column) = -1.0;
    lp.row_upper[r] = (spec.constraint_limits[h] - lin.constraints0[h]) / sh;
    ++r;
  }
  MBOPT_CHECK(r == rows, "row count mismatch");
  return out;
}

}  // namespace mbopt::slp
