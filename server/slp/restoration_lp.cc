#include "server/slp/restoration_lp.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/check.h"

namespace mbopt::slp {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

RestorationLp BuildRestorationLp(const ProblemSpec& spec, const SlpOptions& o,
                                 const Linearization& lin, const MoveBox& box, double margin) {
  MBOPT_CHECK(margin > 0, "a restoration aims inside the limits");
  const int n = spec.num_variables();
  RestorationLp out;
  out.step_per_unit.resize(n);
  for (int i = 0; i < n; ++i) {
    const double range = spec.upper[i] - spec.lower[i];
    out.step_per_unit[i] =
        margin * std::max(std::abs(lin.x0[i]), o.move_limit_floor_fraction_of_range * range);
  }
  for (int h = 0; h < spec.num_constraints(); ++h) {
    double reach = lin.constraints0[h];
    for (int i = 0; i < n; ++i) {
      const double gi = lin.constraints_gradient(h, i);
      reach += std::max(gi * box.d_lower[i], gi * box.d_upper[i]);
    }
    // A row that cannot come within the margin of its limit inside the box
    // cannot bind the step.
    if ((reach - spec.constraint_limits[h]) / spec.constraint_scales[h] + margin > 0) {
      out.kept_constraints.push_back(h);
    }
  }
  const int columns = 2 * n + 1;
  out.s_column = 2 * n;
  const int rows = 2 * n + static_cast<int>(out.kept_constraints.size());

  lp::LinearProgram& lp = out.lp;
  lp.objective = Eigen::VectorXd::Zero(columns);
  lp.column_lower.resize(columns);
  lp.column_upper.resize(columns);
  for (int i = 0; i < n; ++i) {
    lp.column_lower[i] = box.d_lower[i] / out.step_per_unit[i];
    lp.column_upper[i] = box.d_upper[i] / out.step_per_unit[i];
    lp.column_lower[n + i] = 0.0;
    lp.column_upper[n + i] = kInf;
    lp.objective[n + i] = 1.0;
  }
  lp.column_lower[out.s_column] = 0.0;
  lp.column_upper[out.s_column] = kInf;
  lp.objective[out.s_column] = o.infeasibility_penalty;

  lp.rows = decltype(lp.rows)::Zero(rows, columns);
  lp.row_lower = Eigen::VectorXd::Constant(rows, -kInf);
  lp.row_upper = Eigen::VectorXd::Zero(rows);
  int r = 0;
  for (int i = 0; i < n; ++i) {
    lp.rows(r, i) = 1.0;
    lp.rows(r, n + i) = -1.0;
    ++r;
    lp.rows(r, i) = -1.0;
    lp.rows(r, n + i) = -1.0;
    ++r;
  }
  for (int h : out.kept_constraints) {
    const double sh = spec.constraint_scales[h];
    lp.rows.row(r).head(n) =
        lin.constraints_gradient.row(h).cwiseProduct(out.step_per_unit.transpose()) /
        (sh * margin);
    lp.rows(r, out.s_column) = -1.0;
    lp.row_upper[r] = ((spec.constraint_limits[h] - lin.constraints0[h]) / sh - margin) / margin;
    ++r;
  }
  MBOPT_CHECK(r == rows, "row count mismatch");
  return out;
}

Eigen::VectorXd RestorationStep(const RestorationLp& rlp, const Eigen::VectorXd& solution) {
  const Eigen::Index n = rlp.step_per_unit.size();
  return solution.head(n).cwiseProduct(rlp.step_per_unit);
}

}  // namespace mbopt::slp
