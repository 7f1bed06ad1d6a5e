// A linear program in the form the SLP core builds every cycle, and the
// interface of a solver for it. No solver library is visible here: the CLP
// implementation lives behind make_clp_lp_solver.h, the only header that
// knows CLP exists.
//
//   minimize    objective . x
//   subject to  row_lower <= A x <= row_upper
//               column_lower <= x <= column_upper
//
// Infinite bounds are written as +/- std::numeric_limits<double>::infinity().
#pragma once

#include <memory>
#include <string>

#include <Eigen/Dense>

namespace mbopt::lp {

struct LinearProgram {
  Eigen::VectorXd objective;       // n
  Eigen::VectorXd column_lower;    // n
  Eigen::VectorXd column_upper;    // n
  // Dense: the SLP's rows are gradients, which are dense. Row-major so that a
  // row is one constraint.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows;  // m x n
  Eigen::VectorXd row_lower;       // m
  Eigen::VectorXd row_upper;       // m
};

enum class LpStatus {
  kOptimal,
  kInfeasible,
  kUnbounded,
  kIterationLimit,
  kTimeLimit,
  kNumericalFailure,  // the solver gave up or threw; `message` says why
};

const char* LpStatusName(LpStatus status);

struct LpSolution {
  LpStatus status = LpStatus::kNumericalFailure;
  Eigen::VectorXd x;             // n; meaningful when status == kOptimal
  Eigen::VectorXd row_duals;     // m
  Eigen::VectorXd reduced_costs; // n
  double objective_value = 0.0;
  int iterations = 0;
  bool warm_started = false;     // true when the previous basis was reused
  std::string message;
};

// Which LP the simplex method works on. The answer (x, duals, reduced costs)
// is the same; the work is not: a tall LP (many rows, few columns, like the
// SLP's time-gridded constraints) is much cheaper through its dual, whose
// basis has one row per column of the original.
enum class LpFormulation {
  kAuto,    // the dual when rows > 2 * columns, else the primal
  kPrimal,
  kDual,
};

struct LpSolverOptions {
  int max_iterations = 100000;
  double max_seconds = 60.0;  // CLP's own limit; not used for determinism
  LpFormulation formulation = LpFormulation::kAuto;
};

// Solves a sequence of LPs, reusing the previous optimal basis when the next
// LP has the same shape. Implementations must be deterministic: the same
// sequence of Solve() calls gives bit-identical solutions. Not thread-safe;
// one solver per job.
class LpSolver {
 public:
  virtual ~LpSolver() = default;
  virtual LpSolution Solve(const LinearProgram& lp) = 0;
  // Forget the stored basis; the next Solve() starts cold.
  virtual void ResetWarmStart() = 0;
};

}  // namespace mbopt::lp
