// The stopping rule's first-order optimality measure (cycle_lp.h,
// OptimalityResidual) on hand-made linearizations whose KKT conditions can
// be worked out by hand, and the choice of the run's result (best_design.h).
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "server/lp/make_clp_lp_solver.h"
#include "server/slp/best_design.h"
#include "server/slp/cycle_lp.h"

namespace mbopt::slp {
namespace {

constexpr double kTol = 1e-12;

struct Solved {
  MoveBox box;
  CycleLp lp;
  lp::LpSolution solution;
  double residual = 0;
};

Solved Solve(const ProblemSpec& spec, const Linearization& lin, double move_limit) {
  const SlpOptions options;
  Solved out;
  out.box = ComputeMoveBox(spec, options, lin.x0,
                           Eigen::VectorXd::Constant(spec.num_variables(), move_limit), lin.frozen);
  out.lp = BuildCycleLp(spec, options, lin, out.box);
  out.solution = lp::MakeClpLpSolver()->Solve(out.lp.lp);
  EXPECT_EQ(out.solution.status, lp::LpStatus::kOptimal);
  out.residual = OptimalityResidual(spec, options, lin, out.box, out.lp, out.solution);
  return out;
}

ProblemSpec Box(int n, double lower, double upper, int constraints = 0) {
  ProblemSpec s;
  s.lower = Eigen::VectorXd::Constant(n, lower);
  s.upper = Eigen::VectorXd::Constant(n, upper);
  s.initial = Eigen::VectorXd::Constant(n, 0.5 * (lower + upper));
  for (int i = 0; i < n; ++i) s.variable_names.push_back("x" + std::to_string(i));
  s.constraint_limits = Eigen::VectorXd::Constant(constraints, 2.0);
  s.constraint_scales = Eigen::VectorXd::Constant(constraints, 2.0);
  for (int h = 0; h < constraints; ++h) s.constraint_names.push_back("g");
  return s;
}

Linearization Lin(const Eigen::VectorXd& x0, double f0, const Eigen::RowVectorXd& grad) {
  Linearization lin;
  lin.x0 = x0;
  lin.terms0 = Eigen::VectorXd::Constant(1, f0);
  lin.terms_gradient = grad;
  lin.constraints0 = Eigen::VectorXd(0);
  lin.constraints_gradient = Eigen::MatrixXd(0, x0.size());
  lin.frozen.assign(static_cast<size_t>(x0.size()), false);
  return lin;
}

TEST(OptimalityResidual, GradientHeldBackByAMoveLimitIsTheResidual) {
  // F = 3 + 1.5 x at x0 = 2 in [0, 10]: the LP steps to the move limit
  // and only it holds the gradient back. r = |dF/dx| * max(|x0|, 0.01 * 10) / |F0|
  // = 1.5 * 2 / 3 = 1, whatever the move limit.
  const ProblemSpec spec = Box(1, 0.0, 10.0);
  const Linearization lin = Lin(Eigen::VectorXd::Constant(1, 2.0), 3.0, Eigen::RowVectorXd::Constant(1, 1.5));
  EXPECT_NEAR(Solve(spec, lin, 0.2).residual, 1.0, kTol);
  EXPECT_NEAR(Solve(spec, lin, 0.01).residual, 1.0, kTol);
}

TEST(OptimalityResidual, GradientHeldBackByADesignBoundIsAMultiplierNotAResidual) {
  // Same F at x0 = 0, the lower bound: dF/dx > 0 is balanced by the bound's
  // multiplier, a KKT point.
  const ProblemSpec spec = Box(1, 0.0, 10.0);
  const Linearization lin = Lin(Eigen::VectorXd::Zero(1), 3.0, Eigen::RowVectorXd::Constant(1, 1.5));
  EXPECT_NEAR(Solve(spec, lin, 0.2).residual, 0.0, kTol);
}

TEST(OptimalityResidual, ABoundTheBoxReachesAwayFromX0IsNoMultiplier) {
  // F = 3 + 1.5 x at x0 = 0.5 in [0, 10] with a box of half-width 1: the LP
  // steps onto the lower bound, but x0 is not on it, so nothing but the
  // box holds the gradient back there: r = 1.5 * 0.5 / 3.75 = 0.2.
  const ProblemSpec spec = Box(1, 0.0, 10.0);
  const Linearization lin = Lin(Eigen::VectorXd::Constant(1, 0.5), 3.75, Eigen::RowVectorXd::Constant(1, 1.5));
  EXPECT_NEAR(Solve(spec, lin, 2.0).residual, 0.2, kTol);
}

TEST(OptimalityResidual, ActiveConstraintBalancingTheGradientIsAKktPoint) {
  // min -(x1 + x2) s.t. x1 + x2 <= 2 at x0 = (1, 1), on the constraint: the
  // constraint's multiplier 1 balances the gradient; the LP may slide along
  // the face to a move limit, but no reduced cost is left there.
  ProblemSpec spec = Box(2, -10.0, 10.0, 1);
  Linearization lin = Lin(Eigen::Vector2d(1.0, 1.0), -2.0, Eigen::RowVector2d(-1.0, -1.0));
  lin.constraints0 = Eigen::VectorXd::Constant(1, 2.0);
  lin.constraints_gradient = Eigen::RowVector2d(1.0, 1.0);
  EXPECT_NEAR(Solve(spec, lin, 0.2).residual, 0.0, 1e-9);
  // Off the optimum along the face (a steeper x1), the move limit holds the
  // difference: r = |(-2) - (-1) * 1| * |x0| / |F0|... on x1 or x2, > 0.
  lin.terms_gradient = Eigen::RowVector2d(-2.0, -1.0);
  EXPECT_GT(Solve(spec, lin, 0.2).residual, 0.1);
}

TEST(OptimalityResidual, InfeasibleLinearizationIsNoKktPoint) {
  // g = x1 + x2 = 8 with limit 2 and a box too small to reach it.
  ProblemSpec spec = Box(2, -10.0, 10.0, 1);
  Linearization lin = Lin(Eigen::Vector2d(4.0, 4.0), 1.0, Eigen::RowVector2d(0.0, 0.0));
  lin.constraints0 = Eigen::VectorXd::Constant(1, 8.0);
  lin.constraints_gradient = Eigen::RowVector2d(1.0, 1.0);
  EXPECT_EQ(Solve(spec, lin, 0.1).residual, std::numeric_limits<double>::infinity());
}

TEST(OptimalityResidual, MinMaxStationaryCombinationOfTermsIsAKktPoint) {
  // F = max(x, -x) = |x| at x0 = 0 in [-1, 1]: the two terms' multipliers
  // (1/2 each) cancel; with a floor of 1 % of the range on the box.
  ProblemSpec spec = Box(1, -1.0, 1.0);
  spec.objective_form = ObjectiveForm::kMinMax;
  spec.num_objective_terms = 2;
  Linearization lin = Lin(Eigen::VectorXd::Zero(1), 0.0, Eigen::RowVectorXd::Zero(1));
  lin.terms0 = Eigen::Vector2d(0.5, 0.5);  // F = 0.5 + |x|
  lin.terms_gradient = Eigen::MatrixXd(2, 1);
  lin.terms_gradient << 1.0, -1.0;
  EXPECT_NEAR(Solve(spec, lin, 0.2).residual, 0.0, kTol);
  // Off centre, one term rules, and the move limit holds it: r = 1 * 0.5 / 1.0.
  lin.x0 = Eigen::VectorXd::Constant(1, 0.5);
  lin.terms0 = Eigen::Vector2d(1.0, 0.0);
  EXPECT_NEAR(Solve(spec, lin, 0.2).residual, 0.5, kTol);
}

DesignPoint Point(double x, double f, double g) { return DesignPoint{Eigen::VectorXd::Constant(1, x), f, g}; }

TEST(BestDesign, FeasibleBeatsLowerObjectiveAndLowerObjectiveWinsAmongFeasible) {
  BestDesign best;
  best.Offer(Point(1, 5.0, 0.2));     // infeasible
  best.Offer(Point(2, 9.0, 0.0));     // feasible: on its limit
  EXPECT_EQ(best.best()->x[0], 2);
  best.Offer(Point(3, 4.0, 0.01));    // lower F, infeasible
  EXPECT_EQ(best.best()->x[0], 2);
  best.Offer(Point(4, 8.0, -0.3));    // lower F, feasible
  EXPECT_EQ(best.best()->x[0], 4);
  best.Offer(Point(5, 8.0, -0.5));    // a tie keeps the earlier
  EXPECT_EQ(best.best()->x[0], 4);
}

TEST(BestDesign, WithinTheViolationToleranceIsNotFeasible) {
  // A two-load-case run: a design violating a limit by 0.0012 (inside the
  // 0.005 stopping tolerance) with F = 10.0996, and a later feasible one
  // with F = 10.117: the result is the feasible one.
  BestDesign best;
  best.Offer(Point(1, 10.0996, 0.0012));
  best.Offer(Point(2, 10.117, -1e-9));
  EXPECT_EQ(best.best()->x[0], 2);
}

TEST(BestDesign, LeastViolationAmongInfeasibleAndFailedAnalysesIgnored) {
  BestDesign best;
  best.Offer(Point(1, 1.0, 0.5));
  best.Offer(Point(2, 2.0, 0.1));
  best.Offer(Point(3, std::nan(""), 0.0));
  EXPECT_EQ(best.best()->x[0], 2);
}

TEST(BestDesign, RecordOffersX0ThenTrial) {
  BestDesign best;
  CycleRecord r;
  r.x0 = Eigen::VectorXd::Constant(1, 1.0);
  r.objective_x0 = 2.0;
  r.max_violation_x0 = 0.0;
  r.x_trial = Eigen::VectorXd::Constant(1, 2.0);
  r.objective_trial = 2.5;  // an accepted step that made F worse
  r.max_violation_trial = 0.0;
  best.OfferRecord(r);
  EXPECT_EQ(best.best()->x[0], 1.0);
  EXPECT_EQ(best.best()->objective, 2.0);
}

}  // namespace
}  // namespace mbopt::slp
