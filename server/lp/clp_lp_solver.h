// LpSolver backed by COIN-OR CLP's simplex (ClpSimplex). Construct it through
// MakeClpLpSolver (make_clp_lp_solver.h); this header exists so that the one
// translation unit that includes ClpSimplex.hpp has a class to define.
//
// Formulation (LpSolverOptions::formulation): CLP works either on the LP as
// given or on its dual
//   minimize   -rl.y+ + ru.y- - l.d+ + u.d-
//   subject to A^T (y+ - y-) + d+ - d- = c,  y+, y-, d+, d- >= 0
// (one column per finite bound), whose basis is only n x n: for the SLP's
// tall LPs (1000 rows, 11 columns) this is several times faster. x is read
// back from the dual's row duals (x = -pi), the row duals as y+ - y-, the
// reduced costs as d+ - d-. When the dual says "infeasible" (the original is
// unbounded or infeasible) or fails, the LP is solved again as given, so the
// status is always the original LP's.
//
// Warm start: the ClpSimplex model stays alive between Solve() calls. When the
// next LP has the same number of rows and columns and the same pattern of
// finite bounds, its coefficients and bounds are written into the model in
// place and the previous basis is the starting point (primal simplex when only
// the objective of an LP solved as given changed, dual simplex otherwise). A
// different shape rebuilds the model and starts cold. A warm or dual-form
// solution whose primal residuals do not check out against the input LP is
// discarded and the LP is solved again cold, as given.
//
// CLP prints nothing: its message handler is silenced. Nothing it throws
// (CoinError is not a std::exception) leaves Solve(): it becomes
// LpStatus::kNumericalFailure with the message.
#pragma once

#include <memory>

#include "server/lp/linear_program.h"

namespace mbopt::lp {

class ClpLpSolver final : public LpSolver {
 public:
  explicit ClpLpSolver(const LpSolverOptions& options);
  ~ClpLpSolver() override;
  ClpLpSolver(const ClpLpSolver&) = delete;
  ClpLpSolver& operator=(const ClpLpSolver&) = delete;

  LpSolution Solve(const LinearProgram& lp) override;
  void ResetWarmStart() override;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mbopt::lp
