// A sum of maxima, F = sum_g max_{j in g} f_j: the core's form for a weighted
// sum whose terms are peaks. Each group gets its own bound variable; the
// optimum of the sum differs from the optimum of the largest term, so a core
// that took the largest (or one bound for all) lands elsewhere.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "server/lp/make_clp_lp_solver.h"
#include "server/slp/cycle_lp.h"
#include "tests/slp/test_problems.h"
#include "tests/slp_testing/drive_optimizer.h"

namespace mbopt::slp::testing {
namespace {

Evaluator FromFunction(std::function<void(const Eigen::VectorXd&, Eigen::VectorXd*, Eigen::VectorXd*)> f) {
  return [f](const AnalysisRequest& req) {
    AnalysisResult r;
    r.outcome = AnalysisOutcome::kOk;
    f(req.x, &r.objective_terms, &r.constraint_values);
    return r;
  };
}

RunOutcome RunToEnd(const ProblemSpec& spec, const Evaluator& eval, const SlpOptions& o) {
  EXPECT_TRUE(spec.Validate().ok()) << spec.Validate();
  SlpOptimizer optimizer(spec, o, lp::MakeClpLpSolver());
  absl::StatusOr<RunOutcome> out = RunToCompletion(optimizer, eval);
  EXPECT_TRUE(out.ok()) << out.status();
  return out.ok() ? *out : RunOutcome{};
}

// max_t (x1 - t)^2 over t in {0, 1} plus 2 max_t (x2 - 2t)^2 over t in {0,
// 0.5, 1}: the peaks are least at x1 = 0.5 (0.25) and x2 = 1 (1), so F =
// 0.25 + 2 = 2.25. (The largest of all five terms is 2 at best, for any x1
// with both of its terms <= 2: a core that took the largest reports 2.)
ProblemSpec TwoPeaks(std::vector<double> initial) {
  ProblemSpec spec = MakeSpec({-2, -3}, {2, 3}, initial, {}, {});
  spec.objective_form = ObjectiveForm::kSumOfMax;
  spec.num_objective_terms = 5;
  spec.objective_group_sizes = {2, 3};
  return spec;
}

void TwoPeaksValues(const Eigen::VectorXd& x, Eigen::VectorXd* f, Eigen::VectorXd* g) {
  f->resize(5);
  *f << x[0] * x[0], (x[0] - 1) * (x[0] - 1), 2 * x[1] * x[1], 2 * (x[1] - 1) * (x[1] - 1),
      2 * (x[1] - 2) * (x[1] - 2);
  g->resize(0);
}

TEST(SumOfMax, ObjectiveValueAddsTheLargestOfEachGroup) {
  const ProblemSpec spec = TwoPeaks({0.9, 0.0});
  Eigen::VectorXd f, g;
  TwoPeaksValues(Eigen::Vector2d(0.9, 0.0), &f, &g);
  EXPECT_DOUBLE_EQ(ObjectiveValue(spec, f), 0.81 + 8.0);
  ProblemSpec minmax = spec;
  minmax.objective_form = ObjectiveForm::kMinMax;
  minmax.objective_group_sizes.clear();
  EXPECT_DOUBLE_EQ(ObjectiveValue(minmax, f), 8.0);
}

TEST(SumOfMax, ReachesTheClosedFormOfTwoWeightedPeaks) {
  for (const std::vector<double>& start : {std::vector<double>{0.9, 0.0}, std::vector<double>{-1.5, 2.5}}) {
    const RunOutcome out = RunToEnd(TwoPeaks(start), FromFunction(TwoPeaksValues), SlpOptions{});
    EXPECT_EQ(out.state, RunState::kConverged) << start[0];
    EXPECT_NEAR(out.objective, 2.25, 2.25 * 1e-3) << start[0];
    EXPECT_NEAR(out.design[0], 0.5, 0.02) << start[0];
    EXPECT_NEAR(out.design[1], 1.0, 0.02) << start[0];
  }
}

// |x1 - 1| + 2 |x2 - 2| + 0.5 x1 s.t. x1 + x2 <= 1: the third group is an
// ordinary summand of one term. Moving x1 costs 1 - 0.5 per unit below 1,
// moving x2 costs 2, so the limit is met by x1 alone: x = (-1, 2), F = 1.5.
TEST(SumOfMax, NonsmoothSumWithALinearSummandAndALimit) {
  ProblemSpec spec = MakeSpec({-5, -5}, {5, 5}, {3.0, 0.5}, {1.0}, {1.0});
  spec.objective_form = ObjectiveForm::kSumOfMax;
  spec.num_objective_terms = 5;
  spec.objective_group_sizes = {2, 2, 1};
  const Evaluator eval = FromFunction([](const Eigen::VectorXd& x, Eigen::VectorXd* f, Eigen::VectorXd* g) {
    f->resize(5);
    *f << x[0] - 1, 1 - x[0], 2 * (x[1] - 2), 2 * (2 - x[1]), 0.5 * x[0];
    *g = Eigen::VectorXd::Constant(1, x[0] + x[1]);
  });
  const RunOutcome out = RunToEnd(spec, eval, SlpOptions{});
  EXPECT_EQ(out.state, RunState::kConverged);
  EXPECT_NEAR(out.objective, 1.5, 1e-3);
  EXPECT_NEAR(out.design[0], -1.0, 1e-3);
  EXPECT_NEAR(out.design[1], 2.0, 1e-3);
  EXPECT_LE(out.max_violation, 0.0);
}

TEST(SumOfMax, CycleLpHasOneBoundVariablePerGroup) {
  ProblemSpec spec = MakeSpec({-5}, {5}, {1.0}, {}, {});
  spec.objective_form = ObjectiveForm::kSumOfMax;
  spec.num_objective_terms = 3;
  spec.objective_group_sizes = {2, 1};
  const SlpOptions o;
  Linearization lin;
  lin.x0 = Eigen::VectorXd::Constant(1, 1.0);
  lin.terms0 = Eigen::Vector3d(1.0, -1.0, 0.5);  // |x| and 0.5 x at x = 1
  lin.terms_gradient = Eigen::MatrixXd(3, 1);
  lin.terms_gradient << 1.0, -1.0, 0.5;
  lin.constraints0.resize(0);
  lin.constraints_gradient.resize(0, 1);
  lin.frozen = {false};
  const MoveBox box = ComputeMoveBox(spec, o, lin.x0, Eigen::VectorXd::Constant(1, 2.0), {false});
  const CycleLp lp = BuildCycleLp(spec, o, lin, box);
  EXPECT_EQ(lp.beta_column, 1);
  EXPECT_EQ(lp.s_column, 3);
  EXPECT_EQ(lp.kept_terms, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(lp.kept_term_groups, (std::vector<int>{0, 0, 1}));
  const lp::LpSolution s = lp::MakeClpLpSolver()->Solve(lp.lp);
  ASSERT_EQ(s.status, lp::LpStatus::kOptimal);
  // |x| + 0.5 x is least at x = 0: the step is -1.
  EXPECT_NEAR(s.x[0], -1.0, 1e-9);
  EXPECT_NEAR(PredictedObjective(spec, lin, Eigen::VectorXd::Constant(1, -1.0), &lp), 0.0, 1e-12);
  EXPECT_GT(OptimalityResidual(spec, o, lin, box, lp, s), 0.5);  // x0 = 1 is not the optimum

  // At x = 0 (the optimum, a kink of the first group) nothing is left.
  lin.x0[0] = 0.0;
  lin.terms0.setZero();
  const MoveBox box0 = ComputeMoveBox(spec, o, lin.x0, Eigen::VectorXd::Constant(1, 2.0), {false});
  const CycleLp lp0 = BuildCycleLp(spec, o, lin, box0);
  const lp::LpSolution s0 = lp::MakeClpLpSolver()->Solve(lp0.lp);
  ASSERT_EQ(s0.status, lp::LpStatus::kOptimal);
  EXPECT_NEAR(s0.x[0], 0.0, 1e-12);
  EXPECT_LT(OptimalityResidual(spec, o, lin, box0, lp0, s0), 1e-9);
}

TEST(SumOfMax, ValidateChecksTheGroups) {
  ProblemSpec spec = TwoPeaks({0.9, 0.0});
  spec.objective_group_sizes = {2, 2};
  EXPECT_FALSE(spec.Validate().ok());
  spec.objective_group_sizes = {5, 0};
  EXPECT_FALSE(spec.Validate().ok());
  spec.objective_group_sizes = {};
  EXPECT_FALSE(spec.Validate().ok());
  spec.objective_form = ObjectiveForm::kMinMax;
  spec.objective_group_sizes = {2, 3};
  EXPECT_FALSE(spec.Validate().ok());
  spec.objective_group_sizes = {};
  EXPECT_TRUE(spec.Validate().ok());
}

}  // namespace
}  // namespace mbopt::slp::testing
