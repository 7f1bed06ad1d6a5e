// The LP of one cycle: the move-limit box and screening, checked on small
// hand-made linearizations.
#include "server/slp/cycle_lp.h"

#include <gtest/gtest.h>

#include "server/lp/make_clp_lp_solver.h"

namespace mbopt::slp {
namespace {

constexpr double kTol = 1e-12;  // sums and products of a few decimals

ProblemSpec TwoVariables(int constraints) {
  ProblemSpec s;
  s.variable_names = {"a", "b"};
  s.lower = Eigen::Vector2d(0.0, -1.0);
  s.upper = Eigen::Vector2d(10.0, 1.0);
  s.initial = Eigen::Vector2d(5.0, 0.0);
  s.constraint_limits = Eigen::VectorXd::Constant(constraints, 1.0);
  s.constraint_scales = Eigen::VectorXd::Constant(constraints, 1.0);
  for (int h = 0; h < constraints; ++h) s.constraint_names.push_back("g");
  return s;
}

TEST(CycleLp, MoveBoxIsRelativeWithRangeFloorAndClippedToBounds) {
  const ProblemSpec spec = TwoVariables(0);
  const SlpOptions o;  // floor 1 % of the range
  // a: 0.2 * max(9.8, 0.1) = 1.96, clipped above at 10 - 9.8 = 0.2.
  // b at 0: 0.2 * max(0, 0.02) = 0.004.
  const MoveBox box = ComputeMoveBox(spec, o, Eigen::Vector2d(9.8, 0.0),
                                     Eigen::Vector2d(0.2, 0.2), {false, false});
  EXPECT_NEAR(box.half_width[0], 1.96, kTol);
  EXPECT_NEAR(box.d_lower[0], -1.96, kTol);
  EXPECT_NEAR(box.d_upper[0], 0.2, kTol);
  EXPECT_NEAR(box.half_width[1], 0.004, kTol);
  EXPECT_NEAR(box.d_lower[1], -0.004, kTol);
}

TEST(CycleLp, HeldVariableHasAnEmptyBox) {
  const MoveBox box = ComputeMoveBox(TwoVariables(0), SlpOptions{}, Eigen::Vector2d(5, 0),
                                     Eigen::Vector2d(0.2, 0.2), {true, false});
  EXPECT_EQ(box.d_lower[0], 0.0);
  EXPECT_EQ(box.d_upper[0], 0.0);
}

Linearization Linear(const Eigen::Vector2d& x0, const Eigen::VectorXd& g0,
                     const Eigen::MatrixXd& dg) {
  Linearization lin;
  lin.x0 = x0;
  lin.terms0 = Eigen::VectorXd::Constant(1, 3.0);
  lin.terms_gradient = Eigen::MatrixXd(1, 2);
  lin.terms_gradient << -1.0, 0.0;  // wants a larger
  lin.constraints0 = g0;
  lin.constraints_gradient = dg;
  lin.frozen = {false, false};
  return lin;
}

TEST(CycleLp, ScreeningKeepsNearAndReachableRowsOnly) {
  const ProblemSpec spec = TwoVariables(3);
  const SlpOptions o;
  const Eigen::Vector2d x0(5.0, 0.0);
  const MoveBox box = ComputeMoveBox(spec, o, x0, Eigen::Vector2d(0.2, 0.2), {false, false});
  // Box for a: |d| <= 1. Row 0: g = 0.9 (normalized -0.1): near, kept.
  // Row 1: g = -1 (normalized -2) with slope 0.5 in a: can reach -0.5, out.
  // Row 2: g = -1 with slope 3 in a: can reach 2 > 1, kept.
  Eigen::VectorXd g0(3);
  g0 << 0.9, -1.0, -1.0;
  Eigen::MatrixXd dg(3, 2);
  dg << 0.0, 0.0, 0.5, 0.0, 3.0, 0.0;
  const CycleLp lp = BuildCycleLp(spec, o, Linear(x0, g0, dg), box);
  EXPECT_EQ(lp.kept_constraints, (std::vector<int>{0, 2}));
  EXPECT_EQ(lp.lp.rows.rows(), 2);
  // Solved, row 2 limits a: -1 + 3 d <= 1 -> d <= 2/3.
  auto solver = lp::MakeClpLpSolver();
  const lp::LpSolution s = solver->Solve(lp.lp);
  ASSERT_EQ(s.status, lp::LpStatus::kOptimal);
  EXPECT_NEAR(s.x[0], 2.0 / 3.0, 1e-9);
  EXPECT_NEAR(s.x[lp.s_column], 0.0, 1e-12);
}

TEST(CycleLp, InfeasibilityVariableRelaxesUnreachableConstraints) {
  const ProblemSpec spec = TwoVariables(1);
  const SlpOptions o;
  const Eigen::Vector2d x0(5.0, 0.0);
  const MoveBox box = ComputeMoveBox(spec, o, x0, Eigen::Vector2d(0.2, 0.2), {false, false});
  // g = 3 > 1 with slope 1 in a: the box (|d| <= 1) brings it to 2 at best.
  Eigen::VectorXd g0 = Eigen::VectorXd::Constant(1, 3.0);
  Eigen::MatrixXd dg(1, 2);
  dg << 1.0, 0.0;
  const CycleLp lp = BuildCycleLp(spec, o, Linear(x0, g0, dg), box);
  auto solver = lp::MakeClpLpSolver();
  const lp::LpSolution s = solver->Solve(lp.lp);
  ASSERT_EQ(s.status, lp::LpStatus::kOptimal);
  // The penalty makes reducing the violation worth more than the objective.
  EXPECT_NEAR(s.x[0], -1.0, 1e-9);
  EXPECT_NEAR(s.x[lp.s_column], 1.0, 1e-9);  // normalized violation left
}

TEST(CycleLp, MinMaxKeepsTermsThatCanOvertakeTheMaximum) {
  ProblemSpec spec = TwoVariables(0);
  spec.objective_form = ObjectiveForm::kMinMax;
  spec.num_objective_terms = 3;
  const SlpOptions o;
  const Eigen::Vector2d x0(5.0, 0.0);
  const MoveBox box = ComputeMoveBox(spec, o, x0, Eigen::Vector2d(0.2, 0.2), {false, false});
  Linearization lin;
  lin.x0 = x0;
  lin.terms0 = Eigen::Vector3d(10.0, 1.0, 1.0);
  lin.terms_gradient = Eigen::MatrixXd(3, 2);
  // Term 0 (the max) can fall to 9 in the box; term 1 can rise to 1.5 (out);
  // term 2 can rise to 1 + 9 = 10 (kept, although far below the max now).
  lin.terms_gradient << 1.0, 0.0, 0.5, 0.0, 9.0, 0.0;
  lin.constraints0.resize(0);
  lin.constraints_gradient.resize(0, 2);
  lin.frozen = {false, false};
  const CycleLp lp = BuildCycleLp(spec, o, lin, box);
  EXPECT_EQ(lp.kept_terms, (std::vector<int>{0, 2}));
  EXPECT_EQ(lp.beta_column, 2);
  EXPECT_EQ(lp.s_column, 3);
}

}  // namespace
}  // namespace mbopt::slp
