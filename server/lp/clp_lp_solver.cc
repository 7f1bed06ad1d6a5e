#include "server/lp/clp_lp_solver.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <string>
#include <vector>

#include "server/lp/make_clp_lp_solver.h"

#include "ClpDualRowDantzig.hpp"
#include "ClpPrimalColumnDantzig.hpp"
#include "ClpSimplex.hpp"
#include "CoinError.hpp"
#include "CoinFinite.hpp"
#include "CoinMessageHandler.hpp"

namespace mbopt::lp {
namespace {

// Swallows every CLP message: a library must not write to the console of the
// server it runs in. Solver outcomes reach the caller through LpSolution.
class SilentMessageHandler : public CoinMessageHandler {
 public:
  SilentMessageHandler() { setLogLevel(0); }
  int print() override { return 0; }
  CoinMessageHandler* clone() const override { return new SilentMessageHandler(*this); }
};

// CLP writes infinite bounds as +/- COIN_DBL_MAX.
double ToClpBound(double value) {
  if (value == std::numeric_limits<double>::infinity()) return COIN_DBL_MAX;
  if (value == -std::numeric_limits<double>::infinity()) return -COIN_DBL_MAX;
  return value;
}

bool HasNoNaN(const Eigen::VectorXd& v) {
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (std::isnan(v[i])) return false;
  }
  return true;
}

std::string CheckShape(const LinearProgram& lp) {
  const Eigen::Index n = lp.objective.size();
  const Eigen::Index m = lp.rows.rows();
  if (lp.column_lower.size() != n || lp.column_upper.size() != n) {
    return "column bounds do not have one entry per column";
  }
  if (m > 0 && lp.rows.cols() != n) return "row matrix has the wrong number of columns";
  if (lp.row_lower.size() != m || lp.row_upper.size() != m) {
    return "row bounds do not have one entry per row";
  }
  if (!lp.objective.allFinite() || !lp.rows.allFinite()) {
    return "objective or constraint matrix contains NaN or infinity";
  }
  if (!HasNoNaN(lp.column_lower) || !HasNoNaN(lp.column_upper) ||
      !HasNoNaN(lp.row_lower) || !HasNoNaN(lp.row_upper)) {
    return "a bound is NaN";
  }
  return "";
}

// Largest violation of the LP's rows and column bounds by x, each relative to
// 1 + the magnitude of the quantities involved.
double RelativePrimalResidual(const LinearProgram& lp, const Eigen::VectorXd& x) {
  double worst = 0.0;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const double lo = lp.column_lower[j] - x[j];
    const double hi = x[j] - lp.column_upper[j];
    worst = std::max(worst, std::max(lo, hi) / (1.0 + std::abs(x[j])));
  }
  for (Eigen::Index i = 0; i < lp.rows.rows(); ++i) {
    double activity = 0.0;
    double magnitude = 1.0;
    for (Eigen::Index j = 0; j < x.size(); ++j) {
      const double term = lp.rows(i, j) * x[j];
      activity += term;
      magnitude += std::abs(term);
    }
    const double lo = lp.row_lower[i] - activity;
    const double hi = activity - lp.row_upper[i];
    worst = std::max(worst, std::max(lo, hi) / magnitude);
  }
  return worst;
}

// Warm and dual-form solutions must satisfy the input LP to this (relative)
// before they are trusted; CLP's own feasibility tolerance is 1e-7 on the
// scaled problem.
constexpr double kResidualTolerance = 1e-7;

// startFinishOptions bit 1 of ClpSimplex::dual/primal: keep work areas and the
// factorization allocated between solves (the next LP has the same shape).
constexpr int kKeepWorkAreas = 1;

enum class Form { kPrimal, kDual };

// Which bounds are finite, row by row then column by column: the dual form's
// columns exist only for finite bounds, so a warm update needs the same set.
std::vector<char> FinitePattern(const LinearProgram& lp) {
  std::vector<char> pattern;
  pattern.reserve(lp.row_lower.size() + lp.column_lower.size());
  auto code = [](double lo, double hi) {
    return static_cast<char>((std::isfinite(lo) ? 1 : 0) | (std::isfinite(hi) ? 2 : 0));
  };
  for (Eigen::Index i = 0; i < lp.row_lower.size(); ++i) {
    pattern.push_back(code(lp.row_lower[i], lp.row_upper[i]));
  }
  for (Eigen::Index j = 0; j < lp.column_lower.size(); ++j) {
    pattern.push_back(code(lp.column_lower[j], lp.column_upper[j]));
  }
  return pattern;
}

// One column of the dual form: the multiplier of a finite row bound
// (row >= 0) or of a finite column bound (column >= 0); sign +1 for a lower
// bound, -1 for an upper one.
struct DualColumn {
  int row = -1;
  int column = -1;
  double sign = 1;
};

std::vector<DualColumn> DualColumns(const LinearProgram& lp) {
  std::vector<DualColumn> cols;
  for (int i = 0; i < static_cast<int>(lp.row_lower.size()); ++i) {
    if (std::isfinite(lp.row_lower[i])) cols.push_back({i, -1, +1});
    if (std::isfinite(lp.row_upper[i])) cols.push_back({i, -1, -1});
  }
  for (int j = 0; j < static_cast<int>(lp.column_lower.size()); ++j) {
    if (std::isfinite(lp.column_lower[j])) cols.push_back({-1, j, +1});
    if (std::isfinite(lp.column_upper[j])) cols.push_back({-1, j, -1});
  }
  return cols;
}

// Cost of a dual column: -bound for a lower bound, +bound for an upper one.
double DualCost(const LinearProgram& lp, const DualColumn& d) {
  if (d.row >= 0) return d.sign > 0 ? -lp.row_lower[d.row] : lp.row_upper[d.row];
  return d.sign > 0 ? -lp.column_lower[d.column] : lp.column_upper[d.column];
}

}  // namespace

class ClpLpSolver::Impl {
 public:
  explicit Impl(const LpSolverOptions& options) : options_(options) {}

  LpSolution Solve(const LinearProgram& lp) {
    const std::string shape_error = CheckShape(lp);
    if (!shape_error.empty()) {
      LpSolution out;
      out.status = LpStatus::kNumericalFailure;
      out.message = "invalid LP: " + shape_error;
      return out;
    }
    try {
      const Form form = ChooseForm(lp);
      const bool can_warm = model_ != nullptr && has_basis_ && form == form_ &&
                            lp.objective.size() == last_.objective.size() &&
                            lp.rows.rows() == last_.rows.rows() &&
                            FinitePattern(lp) == pattern_;
      if (can_warm) {
        LpSolution out = SolveWarm(lp);
        if (Trustworthy(lp, out)) {
          Remember(lp, out);
          return out;
        }
      }
      LpSolution out = SolveCold(lp, form);
      if (form == Form::kDual && !Trustworthy(lp, out) &&
          out.status != LpStatus::kIterationLimit && out.status != LpStatus::kTimeLimit) {
        out = SolveCold(lp, Form::kPrimal);
      }
      Remember(lp, out);
      return out;
    } catch (const CoinError& e) {
      return Failure("CLP error in " + e.className() + "::" + e.methodName() + ": " +
                     e.message());
    } catch (const std::exception& e) {
      return Failure(std::string("exception in CLP: ") + e.what());
    } catch (...) {
      return Failure("unknown exception in CLP");
    }
  }

  void ResetWarmStart() {
    model_.reset();
    has_basis_ = false;
  }

 private:
  Form ChooseForm(const LinearProgram& lp) const {
    switch (options_.formulation) {
      case LpFormulation::kPrimal:
        return Form::kPrimal;
      case LpFormulation::kDual:
        return lp.objective.size() > 0 ? Form::kDual : Form::kPrimal;
      case LpFormulation::kAuto:
        break;
    }
    return lp.objective.size() > 0 && lp.rows.rows() > 2 * lp.objective.size()
               ? Form::kDual
               : Form::kPrimal;
  }

  // An answer we can hand out: a final non-optimal status of the LP as given,
  // or an optimum whose x satisfies the input LP.
  bool Trustworthy(const LinearProgram& lp, const LpSolution& out) const {
    if (out.status == LpStatus::kOptimal) {
      return RelativePrimalResidual(lp, out.x) <= kResidualTolerance;
    }
    // The dual form's "infeasible" and failures are settled as given.
    return form_ == Form::kPrimal && out.status != LpStatus::kNumericalFailure;
  }

  LpSolution Failure(std::string message) {
    ResetWarmStart();
    LpSolution out;
    out.status = LpStatus::kNumericalFailure;
    out.message = std::move(message);
    return out;
  }

  void Remember(const LinearProgram& lp, const LpSolution& out) {
    // Only an optimal basis is a good start for the next LP.
    has_basis_ = out.status == LpStatus::kOptimal;
    last_ = lp;
  }

  void Configure(ClpSimplex& model) {
    model.passInMessageHandler(&handler_);
    model.setLogLevel(0);
    model.setRandomSeed(1234567);
    model.setMaximumIterations(options_.max_iterations);
    model.setMaximumSeconds(options_.max_seconds);
    // Steepest-edge weights cost a pass over every row or column per pivot
    // (and a full recomputation at every warm start); these LPs need only
    // tens of pivots, for which Dantzig's rules are cheaper overall.
    ClpDualRowDantzig dual_pricing;
    model.setDualRowPivotAlgorithm(dual_pricing);
    ClpPrimalColumnDantzig primal_pricing;
    model.setPrimalColumnPivotAlgorithm(primal_pricing);
  }

  LpSolution SolveCold(const LinearProgram& lp, Form form) {
    form_ = form;
    pattern_ = FinitePattern(lp);
    model_ = std::make_unique<ClpSimplex>();
    Configure(*model_);
    if (form == Form::kPrimal) {
      LoadPrimal(lp);
    } else {
      LoadDual(lp);
    }
    model_->dual(0, kKeepWorkAreas);
    LpSolution out = Extract(lp);
    out.warm_started = false;
    return out;
  }

  void LoadPrimal(const LinearProgram& lp) {
    const int n = static_cast<int>(lp.objective.size());
    const int m = static_cast<int>(lp.rows.rows());
    // Column-major, every entry stored (zeros too), so that the element array
    // keeps its layout and a same-shape LP can be written into it in place.
    std::vector<CoinBigIndex> starts(n + 1);
    std::vector<int> indices(static_cast<size_t>(n) * m);
    std::vector<double> values(static_cast<size_t>(n) * m);
    for (int j = 0; j < n; ++j) {
      starts[j] = static_cast<CoinBigIndex>(j) * m;
      for (int i = 0; i < m; ++i) {
        indices[static_cast<size_t>(j) * m + i] = i;
        values[static_cast<size_t>(j) * m + i] = lp.rows(i, j);
      }
    }
    starts[n] = static_cast<CoinBigIndex>(n) * m;
    std::vector<double> col_lo(n), col_up(n), row_lo(m), row_up(m);
    for (int j = 0; j < n; ++j) {
      col_lo[j] = ToClpBound(lp.column_lower[j]);
      col_up[j] = ToClpBound(lp.column_upper[j]);
    }
    for (int i = 0; i < m; ++i) {
      row_lo[i] = ToClpBound(lp.row_lower[i]);
      row_up[i] = ToClpBound(lp.row_upper[i]);
    }
    model_->loadProblem(n, m, starts.data(), indices.data(), values.data(), col_lo.data(),
                        col_up.data(), lp.objective.data(), row_lo.data(), row_up.data());
  }

  void LoadDual(const LinearProgram& lp) {
    const int n = static_cast<int>(lp.objective.size());
    dual_columns_ = DualColumns(lp);
    const int k = static_cast<int>(dual_columns_.size());
    std::vector<CoinBigIndex> starts(k + 1);
    std::vector<int> indices;
    std::vector<double> values;
    std::vector<double> cost(k), col_lo(k, 0.0), col_up(k, COIN_DBL_MAX);
    for (int c = 0; c < k; ++c) {
      const DualColumn& d = dual_columns_[c];
      starts[c] = static_cast<CoinBigIndex>(indices.size());
      if (d.row >= 0) {
        for (int j = 0; j < n; ++j) {
          indices.push_back(j);
          values.push_back(d.sign * lp.rows(d.row, j));
        }
      } else {
        indices.push_back(d.column);
        values.push_back(d.sign);
      }
      cost[c] = DualCost(lp, d);
    }
    starts[k] = static_cast<CoinBigIndex>(indices.size());
    model_->loadProblem(k, n, starts.data(), indices.data(), values.data(), col_lo.data(),
                        col_up.data(), cost.data(), lp.objective.data(), lp.objective.data());
  }

  LpSolution SolveWarm(const LinearProgram& lp) {
    CoinPackedMatrix* matrix = model_->matrix();
    if (matrix == nullptr || !matrix->isColOrdered()) {
      LpSolution out;
      out.status = LpStatus::kNumericalFailure;  // layout changed: caller goes cold
      return out;
    }
    double* elements = matrix->getMutableElements();
    const CoinBigIndex* starts = matrix->getVectorStarts();
    const int* indices = matrix->getIndices();
    const int* lengths = matrix->getVectorLengths();
    const int n = static_cast<int>(lp.objective.size());
    const int m = static_cast<int>(lp.rows.rows());
    if (form_ == Form::kPrimal) {
      if (matrix->getNumElements() != static_cast<CoinBigIndex>(n) * m) {
        LpSolution out;
        out.status = LpStatus::kNumericalFailure;
        return out;
      }
      for (int j = 0; j < n; ++j) {
        for (CoinBigIndex e = starts[j]; e < starts[j] + lengths[j]; ++e) {
          elements[e] = lp.rows(indices[e], j);
        }
      }
      double* objective = model_->objective();
      double* col_lo = model_->columnLower();
      double* col_up = model_->columnUpper();
      for (int j = 0; j < n; ++j) {
        objective[j] = lp.objective[j];
        col_lo[j] = ToClpBound(lp.column_lower[j]);
        col_up[j] = ToClpBound(lp.column_upper[j]);
      }
      double* row_lo = model_->rowLower();
      double* row_up = model_->rowUpper();
      for (int i = 0; i < m; ++i) {
        row_lo[i] = ToClpBound(lp.row_lower[i]);
        row_up[i] = ToClpBound(lp.row_upper[i]);
      }
    } else {
      const int k = static_cast<int>(dual_columns_.size());
      double* cost = model_->objective();
      for (int c = 0; c < k; ++c) {
        const DualColumn& d = dual_columns_[c];
        for (CoinBigIndex e = starts[c]; e < starts[c] + lengths[c]; ++e) {
          elements[e] = d.row >= 0 ? d.sign * lp.rows(d.row, indices[e]) : d.sign;
        }
        cost[c] = DualCost(lp, d);
      }
      double* row_lo = model_->rowLower();
      double* row_up = model_->rowUpper();
      for (int j = 0; j < n; ++j) row_lo[j] = row_up[j] = lp.objective[j];
    }
    // Everything may have changed: CLP must rebuild its scaled copies; the
    // status array (the basis) is what carries over.
    model_->setWhatsChanged(ROW_COLUMN_COUNTS_SAME);
    const bool objective_only = lp.rows == last_.rows && lp.row_lower == last_.row_lower &&
                                lp.row_upper == last_.row_upper &&
                                lp.column_lower == last_.column_lower &&
                                lp.column_upper == last_.column_upper;
    if (form_ == Form::kPrimal && objective_only) {
      model_->primal(0, kKeepWorkAreas);  // the old basis stays primal feasible
    } else {
      model_->dual(0, kKeepWorkAreas);
    }
    LpSolution out = Extract(lp);
    out.warm_started = true;
    return out;
  }

  LpSolution Extract(const LinearProgram& lp) {
    LpSolution out;
    out.iterations = model_->numberIterations();
    const int status = model_->problemStatus();
    switch (status) {
      case 0:
        out.status = LpStatus::kOptimal;
        break;
      case 1:
        // As given: infeasible. For the dual form: the original is unbounded
        // or infeasible, which the caller settles by solving it as given.
        out.status = form_ == Form::kPrimal ? LpStatus::kInfeasible : LpStatus::kUnbounded;
        break;
      case 2:
        out.status = form_ == Form::kPrimal ? LpStatus::kUnbounded : LpStatus::kInfeasible;
        break;
      case 3:
        out.status = model_->numberIterations() >= options_.max_iterations
                         ? LpStatus::kIterationLimit
                         : LpStatus::kTimeLimit;
        break;
      default:
        out.status = LpStatus::kNumericalFailure;
        out.message = "CLP stopped with problem status " + std::to_string(status) +
                      ", secondary status " + std::to_string(model_->secondaryStatus());
        break;
    }
    if (form_ == Form::kPrimal) {
      ExtractPrimal(lp, &out);
    } else {
      ExtractDual(lp, &out);
    }
    out.objective_value = lp.objective.dot(out.x);
    return out;
  }

  void ExtractPrimal(const LinearProgram& lp, LpSolution* out) const {
    const int n = static_cast<int>(lp.objective.size());
    const int m = static_cast<int>(lp.rows.rows());
    out->x = Eigen::Map<const Eigen::VectorXd>(model_->primalColumnSolution(), n);
    out->reduced_costs = Eigen::Map<const Eigen::VectorXd>(model_->dualColumnSolution(), n);
    out->row_duals = m > 0 ? Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(
                                 model_->dualRowSolution(), m))
                           : Eigen::VectorXd(0);
  }

  void ExtractDual(const LinearProgram& lp, LpSolution* out) const {
    const int n = static_cast<int>(lp.objective.size());
    const int m = static_cast<int>(lp.rows.rows());
    // The dual's row duals pi satisfy the original's constraints as x = -pi.
    out->x = -Eigen::Map<const Eigen::VectorXd>(model_->dualRowSolution(), n);
    out->row_duals = Eigen::VectorXd::Zero(m);
    out->reduced_costs = Eigen::VectorXd::Zero(n);
    const double* w = model_->primalColumnSolution();
    for (size_t c = 0; c < dual_columns_.size(); ++c) {
      const DualColumn& d = dual_columns_[c];
      if (d.row >= 0) {
        out->row_duals[d.row] += d.sign * w[c];
      } else {
        out->reduced_costs[d.column] += d.sign * w[c];
      }
    }
  }

  LpSolverOptions options_;
  SilentMessageHandler handler_;
  std::unique_ptr<ClpSimplex> model_;
  Form form_ = Form::kPrimal;
  std::vector<char> pattern_;
  std::vector<DualColumn> dual_columns_;
  bool has_basis_ = false;
  LinearProgram last_;
};

ClpLpSolver::ClpLpSolver(const LpSolverOptions& options)
    : impl_(std::make_unique<Impl>(options)) {}
ClpLpSolver::~ClpLpSolver() = default;

LpSolution ClpLpSolver::Solve(const LinearProgram& lp) { return impl_->Solve(lp); }
void ClpLpSolver::ResetWarmStart() { impl_->ResetWarmStart(); }

std::unique_ptr<LpSolver> MakeClpLpSolver(const LpSolverOptions& options) {
  return std::make_unique<ClpLpSolver>(options);
}

}  // namespace mbopt::lp
