// The CLP adapter against LPs small enough to solve by hand.
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "server/lp/linear_program.h"
#include "server/lp/make_clp_lp_solver.h"

namespace mbopt::lp {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Simplex vertices of these well-conditioned LPs are exact up to rounding.
constexpr double kTol = 1e-9;

LinearProgram Make(int n, int m) {
  LinearProgram lp;
  lp.objective = Eigen::VectorXd::Zero(n);
  lp.column_lower = Eigen::VectorXd::Constant(n, -kInf);
  lp.column_upper = Eigen::VectorXd::Constant(n, kInf);
  lp.rows = decltype(lp.rows)::Zero(m, n);
  lp.row_lower = Eigen::VectorXd::Constant(m, -kInf);
  lp.row_upper = Eigen::VectorXd::Constant(m, kInf);
  return lp;
}

// maximize 3x + 2y s.t. x + y <= 4, x + 3y <= 7, x <= 3, x,y >= 0.
// Optimum at x = 3, y = 1 (value 11); duals: row 1 active with y1 = 2,
// row 2 inactive; x's upper bound active with reduced cost -(3 - 2) = -1.
LinearProgram TextbookLp() {
  LinearProgram lp = Make(2, 2);
  lp.objective << -3, -2;
  lp.column_lower << 0, 0;
  lp.column_upper << 3, kInf;
  lp.rows << 1, 1, 1, 3;
  lp.row_upper << 4, 7;
  return lp;
}

TEST(ClpLpSolver, SolvesTextbookLpToItsHandSolution) {
  auto solver = MakeClpLpSolver();
  const LpSolution s = solver->Solve(TextbookLp());
  ASSERT_EQ(s.status, LpStatus::kOptimal) << s.message;
  EXPECT_NEAR(s.x[0], 3.0, kTol);
  EXPECT_NEAR(s.x[1], 1.0, kTol);
  EXPECT_NEAR(s.objective_value, -11.0, kTol);
  EXPECT_FALSE(s.warm_started);
}

TEST(ClpLpSolver, ReturnsRowDualsAndReducedCostsOfTheOptimalBasis) {
  auto solver = MakeClpLpSolver();
  const LpSolution s = solver->Solve(TextbookLp());
  ASSERT_EQ(s.status, LpStatus::kOptimal);
  // Convention: reduced cost d = c - A^T y.
  EXPECT_NEAR(s.row_duals[0], -2.0, kTol);
  EXPECT_NEAR(s.row_duals[1], 0.0, kTol);
  EXPECT_NEAR(s.reduced_costs[0], -1.0, kTol);
  EXPECT_NEAR(s.reduced_costs[1], 0.0, kTol);
}

TEST(ClpLpSolver, SolvesEqualityAndRangedRows) {
  // minimize x + 2y + 3z s.t. x + y + z = 6, 1 <= y - z <= 2, x <= 1, all >= 0.
  // x = 1; y + z = 5 and y - z in [1,2]: y cheaper, so y - z = 2: y = 3.5, z = 1.5.
  LinearProgram lp = Make(3, 2);
  lp.objective << 1, 2, 3;
  lp.column_lower.setZero();
  lp.column_upper << 1, kInf, kInf;
  lp.rows << 1, 1, 1, 0, 1, -1;
  lp.row_lower << 6, 1;
  lp.row_upper << 6, 2;
  auto solver = MakeClpLpSolver();
  const LpSolution s = solver->Solve(lp);
  ASSERT_EQ(s.status, LpStatus::kOptimal);
  EXPECT_NEAR(s.x[0], 1.0, kTol);
  EXPECT_NEAR(s.x[1], 3.5, kTol);
  EXPECT_NEAR(s.x[2], 1.5, kTol);
  EXPECT_NEAR(s.objective_value, 1 + 7 + 4.5, kTol);
}

TEST(ClpLpSolver, SolvesLpWithoutRows) {
  LinearProgram lp = Make(2, 0);
  lp.objective << 1, -1;
  lp.column_lower << -1, -2;
  lp.column_upper << 5, 7;
  auto solver = MakeClpLpSolver();
  const LpSolution s = solver->Solve(lp);
  ASSERT_EQ(s.status, LpStatus::kOptimal) << s.message;
  EXPECT_NEAR(s.x[0], -1.0, kTol);
  EXPECT_NEAR(s.x[1], 7.0, kTol);
}

TEST(ClpLpSolver, ReportsInfeasible) {
  LinearProgram lp = Make(2, 2);
  lp.objective << 1, 1;
  lp.column_lower.setZero();
  lp.rows << 1, 1, 1, 1;
  lp.row_upper << 1, kInf;
  lp.row_lower << -kInf, 2;
  auto solver = MakeClpLpSolver();
  EXPECT_EQ(solver->Solve(lp).status, LpStatus::kInfeasible);
}

TEST(ClpLpSolver, ReportsUnbounded) {
  LinearProgram lp = Make(2, 1);
  lp.objective << -1, 0;
  lp.column_lower.setZero();
  lp.rows << 1, -1;
  lp.row_upper << 1;
  auto solver = MakeClpLpSolver();
  EXPECT_EQ(solver->Solve(lp).status, LpStatus::kUnbounded);
}

TEST(ClpLpSolver, StopsAtIterationLimit) {
  // A random dense LP needs many pivots; one is not enough.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.1, 1.0);
  LinearProgram lp = Make(20, 40);
  for (int j = 0; j < 20; ++j) lp.objective[j] = -u(rng);
  lp.column_lower.setZero();
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 20; ++j) lp.rows(i, j) = u(rng);
    lp.row_upper[i] = 1.0 + u(rng);
  }
  LpSolverOptions options;
  options.max_iterations = 1;
  auto solver = MakeClpLpSolver(options);
  const LpSolution s = solver->Solve(lp);
  EXPECT_EQ(s.status, LpStatus::kIterationLimit);
  EXPECT_STREQ(LpStatusName(s.status), "iteration_limit");
}

TEST(ClpLpSolver, RejectsMalformedLpWithoutCallingClp) {
  LinearProgram lp = TextbookLp();
  lp.row_upper.resize(1);
  auto solver = MakeClpLpSolver();
  const LpSolution s = solver->Solve(lp);
  EXPECT_EQ(s.status, LpStatus::kNumericalFailure);
  EXPECT_NE(s.message.find("row bounds"), std::string::npos) << s.message;

  LinearProgram nan_lp = TextbookLp();
  nan_lp.rows(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(solver->Solve(nan_lp).status, LpStatus::kNumericalFailure);
}

// A sequence of LPs like successive SLP cycles: same shape, data drifting.
LinearProgram DriftingLp(int n, int m, int step) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  LinearProgram lp = Make(n, m);
  const double drift = 0.02 * step;
  for (int j = 0; j < n; ++j) {
    lp.objective[j] = u(rng) + drift * std::sin(j + step);
    lp.column_lower[j] = -1.0 - drift;
    lp.column_upper[j] = 1.0 + 0.5 * drift;
  }
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < n; ++j) lp.rows(i, j) = u(rng) + drift * std::cos(i * j + step);
    lp.row_upper[i] = 0.5 + 0.1 * u(rng) - drift;
  }
  return lp;
}

TEST(ClpLpSolver, WarmStartGivesTheSameOptimumAsColdStart) {
  constexpr int kN = 8, kM = 60;
  auto warm = MakeClpLpSolver();
  int warm_count = 0;
  for (int step = 0; step < 10; ++step) {
    const LinearProgram lp = DriftingLp(kN, kM, step);
    const LpSolution w = warm->Solve(lp);
    auto cold_solver = MakeClpLpSolver();
    const LpSolution c = cold_solver->Solve(lp);
    ASSERT_EQ(w.status, LpStatus::kOptimal) << w.message;
    ASSERT_EQ(c.status, LpStatus::kOptimal) << c.message;
    EXPECT_NEAR(w.objective_value, c.objective_value, 1e-9 * (1 + std::abs(c.objective_value)));
    EXPECT_LT((w.x - c.x).lpNorm<Eigen::Infinity>(), 1e-7) << "step " << step;
    if (w.warm_started) ++warm_count;
  }
  EXPECT_EQ(warm_count, 9);  // every solve after the first reused a basis
}

TEST(ClpLpSolver, WarmStartOnObjectiveChangeOnly) {
  auto solver = MakeClpLpSolver();
  LinearProgram lp = TextbookLp();
  ASSERT_EQ(solver->Solve(lp).status, LpStatus::kOptimal);
  // maximize x + 4y: vertices (0,7/3) = 9.33, (2.5,1.5) = 8.5, (3,1) = 7.
  lp.objective << -1, -4;
  const LpSolution s = solver->Solve(lp);
  ASSERT_EQ(s.status, LpStatus::kOptimal);
  EXPECT_TRUE(s.warm_started);
  EXPECT_NEAR(s.x[0], 0.0, kTol);
  EXPECT_NEAR(s.x[1], 7.0 / 3.0, kTol);
}

TEST(ClpLpSolver, ShapeChangeRebuildsAndResetForgetsBasis) {
  auto solver = MakeClpLpSolver();
  ASSERT_EQ(solver->Solve(DriftingLp(4, 10, 0)).status, LpStatus::kOptimal);
  const LpSolution other = solver->Solve(DriftingLp(4, 11, 0));
  ASSERT_EQ(other.status, LpStatus::kOptimal);
  EXPECT_FALSE(other.warm_started);
  EXPECT_TRUE(solver->Solve(DriftingLp(4, 11, 1)).warm_started);
  solver->ResetWarmStart();
  EXPECT_FALSE(solver->Solve(DriftingLp(4, 11, 2)).warm_started);
}

TEST(ClpLpSolver, SameSequenceGivesBitIdenticalSolutions) {
  auto a = MakeClpLpSolver();
  auto b = MakeClpLpSolver();
  for (int step = 0; step < 6; ++step) {
    const LinearProgram lp = DriftingLp(10, 100, step);
    const LpSolution sa = a->Solve(lp);
    const LpSolution sb = b->Solve(lp);
    ASSERT_EQ(sa.status, sb.status);
    // Bit-identity is the point here.
    EXPECT_EQ(sa.x, sb.x);
    EXPECT_EQ(sa.row_duals, sb.row_duals);
    EXPECT_EQ(sa.iterations, sb.iterations);
  }
}

LpSolverOptions WithForm(LpFormulation form) {
  LpSolverOptions o;
  o.formulation = form;
  return o;
}

TEST(ClpLpSolver, DualFormulationGivesTextbookSolutionDualsAndReducedCosts) {
  auto solver = MakeClpLpSolver(WithForm(LpFormulation::kDual));
  const LpSolution s = solver->Solve(TextbookLp());
  ASSERT_EQ(s.status, LpStatus::kOptimal) << s.message;
  EXPECT_NEAR(s.x[0], 3.0, kTol);
  EXPECT_NEAR(s.x[1], 1.0, kTol);
  EXPECT_NEAR(s.row_duals[0], -2.0, kTol);
  EXPECT_NEAR(s.row_duals[1], 0.0, kTol);
  EXPECT_NEAR(s.reduced_costs[0], -1.0, kTol);
  EXPECT_NEAR(s.reduced_costs[1], 0.0, kTol);
}

// Tall LPs with every kind of bound: ranged, equality, one-sided rows; boxed,
// one-sided and free columns. Both formulations must agree.
LinearProgram MixedTallLp(unsigned seed, int n, int m) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  LinearProgram lp = Make(n, m);
  for (int j = 0; j < n; ++j) {
    lp.objective[j] = u(rng);
    switch (j % 4) {
      case 0: lp.column_lower[j] = -1; lp.column_upper[j] = 1; break;
      case 1: lp.column_lower[j] = -2; break;
      case 2: lp.column_upper[j] = 2; break;
      default: break;  // free
    }
  }
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < n; ++j) lp.rows(i, j) = u(rng);
    switch (i % 5) {
      case 0: lp.row_lower[i] = -1.0 - 0.5 * std::abs(u(rng)); lp.row_upper[i] = 1.0; break;
      case 1: lp.row_lower[i] = lp.row_upper[i] = 0.1 * u(rng); break;
      case 2: lp.row_lower[i] = -1.5; break;
      default: lp.row_upper[i] = 1.0 + 0.5 * std::abs(u(rng)); break;
    }
  }
  return lp;
}

TEST(ClpLpSolver, PrimalAndDualFormulationsAgree) {
  // Optimal vertices of random LPs are nondegenerate, so x and the duals are
  // unique; both forms must find them to solver precision.
  constexpr double kAgree = 1e-7;
  int optimal = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const LinearProgram lp = MixedTallLp(seed, 6, 30);
    auto primal = MakeClpLpSolver(WithForm(LpFormulation::kPrimal));
    auto dual = MakeClpLpSolver(WithForm(LpFormulation::kDual));
    const LpSolution p = primal->Solve(lp);
    const LpSolution d = dual->Solve(lp);
    ASSERT_EQ(p.status, d.status) << "seed " << seed;
    if (p.status != LpStatus::kOptimal) continue;
    ++optimal;
    EXPECT_NEAR(p.objective_value, d.objective_value, kAgree) << "seed " << seed;
    EXPECT_LT((p.x - d.x).lpNorm<Eigen::Infinity>(), kAgree) << "seed " << seed;
    EXPECT_LT((p.row_duals - d.row_duals).lpNorm<Eigen::Infinity>(), kAgree) << "seed " << seed;
    EXPECT_LT((p.reduced_costs - d.reduced_costs).lpNorm<Eigen::Infinity>(), kAgree)
        << "seed " << seed;
  }
  EXPECT_GE(optimal, 10);  // the comparison must have been made
}

TEST(ClpLpSolver, DualFormulationReportsTheOriginalsInfeasibleAndUnbounded) {
  auto solver = MakeClpLpSolver(WithForm(LpFormulation::kDual));
  LinearProgram infeasible = Make(2, 6);
  infeasible.objective << 1, 1;
  for (int i = 0; i < 6; ++i) infeasible.rows.row(i) << 1, 1;
  infeasible.row_upper.setConstant(1.0);
  infeasible.row_lower[5] = 2.0;
  EXPECT_EQ(solver->Solve(infeasible).status, LpStatus::kInfeasible);

  LinearProgram unbounded = Make(2, 6);
  unbounded.objective << -1, 0;
  unbounded.column_lower.setZero();
  for (int i = 0; i < 6; ++i) unbounded.rows.row(i) << 1, -1.0 - i;
  unbounded.row_upper.setConstant(1.0);
  EXPECT_EQ(solver->Solve(unbounded).status, LpStatus::kUnbounded);
}

TEST(ClpLpSolver, DualFormulationWarmStartsLikeThePrimal) {
  auto warm = MakeClpLpSolver(WithForm(LpFormulation::kDual));
  for (int step = 0; step < 8; ++step) {
    const LinearProgram lp = DriftingLp(10, 200, step);
    const LpSolution w = warm->Solve(lp);
    auto cold = MakeClpLpSolver(WithForm(LpFormulation::kPrimal));
    const LpSolution c = cold->Solve(lp);
    ASSERT_EQ(w.status, LpStatus::kOptimal);
    EXPECT_EQ(w.warm_started, step > 0);
    EXPECT_LT((w.x - c.x).lpNorm<Eigen::Infinity>(), 1e-7) << "step " << step;
  }
}

}  // namespace
}  // namespace mbopt::lp
