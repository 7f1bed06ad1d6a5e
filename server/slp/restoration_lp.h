// The LP of a feasibility restoration step (docs/method.md section 7): the
// smallest move from a converged design whose constraints are violated by a
// little (0 < maxg < convergence_violation_tolerance) to one that meets
// them. The violation tolerance is a stopping criterion; the reported
// design must satisfy every constraint (maxg <= 0), and a converged design
// usually sits a rounding of the linearization outside an active limit.
//
// The step and the rows are written in units of the margin, because the
// violations are small: of the order of 1e-9 to 1e-3 of a limit, below or
// near the LP solver's feasibility tolerance (1e-7) in the cycle LP's
// units. With d_i = margin * typical_i * e_i, typical_i = max(|x0_i|,
// floor_fraction * range_i) (the move limits' relative measure, so no
// variable is cheaper to move because of its units):
//
// LP columns: e_0..e_{n-1} (inside the move-limit box), u_0..u_{n-1}
// (u_i >= |e_i|), then s (the infeasibility variable, in margins). Rows:
//   e_i - u_i <= 0 and -e_i - u_i <= 0 for every variable
//   sum_i grad g_h,i typical_i / scale_h e_i - s
//       <= ((c_h - g_h0) / scale_h - margin) / margin
//     for every constraint that could come within the margin of its limit
//   minimize sum_i u_i + penalty * s
// The step moves as little as the linearization allows, and so its own
// linearization error is second order in the (small) violation.
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "server/lp/linear_program.h"
#include "server/slp/cycle_lp.h"
#include "server/slp/options.h"
#include "server/slp/problem.h"

namespace mbopt::slp {

struct RestorationLp {
  lp::LinearProgram lp;
  std::vector<int> kept_constraints;  // row h of the spec for each constraint row
  int s_column = -1;
  Eigen::VectorXd step_per_unit;      // d_i per unit of e_i: margin * typical_i
};

// `margin` (normalized, > 0) is how far inside every limit the step aims.
RestorationLp BuildRestorationLp(const ProblemSpec& spec, const SlpOptions& options,
                                 const Linearization& lin, const MoveBox& box, double margin);

// The step d of a solution of `rlp`.
Eigen::VectorXd RestorationStep(const RestorationLp& rlp, const Eigen::VectorXd& solution);

}  // namespace mbopt::slp
