// Each branch of the move-limit strategy of METHOD.md section 3, driven
// directly through the pure function.
#include "server/slp/move_limit_strategy.h"

#include <gtest/gtest.h>

namespace mbopt::slp {
namespace {

// Factors like 3/4 * 0.2 are exact to a few ulps.
constexpr double kTol = 1e-15;

// One variable, accepted trial, nothing special: every test changes one thing.
MoveLimitInput Baseline() {
  MoveLimitInput in;
  in.max_approximation_error = 0.15;  // between widen (0.10) and narrow (0.25)
  in.max_violation = -0.2;
  in.lp_feasible = true;
  in.objective_x0 = 10.0;
  in.objective_trial = 9.0;  // 10 % better
  in.previous_objective_change = -1.5;
  in.dx_new = Eigen::VectorXd::Constant(1, 0.1);
  in.dx_old = Eigen::VectorXd::Constant(1, 0.1);
  in.on_move_limit = {false};
  in.on_bound = {false};
  in.move_limits = Eigen::VectorXd::Constant(1, 0.2);
  return in;
}

TEST(MoveLimits, UnchangedInsideTheBoxWithAcceptableApproximation) {
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, Baseline());
  EXPECT_TRUE(d.accept);
  EXPECT_TRUE(d.rejection_reason.empty());
  EXPECT_EQ(d.branches[0], MoveLimitBranch::kUnchanged);
  EXPECT_NEAR(d.move_limits_next[0], 0.2, kTol);
}

TEST(MoveLimits, RejectAndShrinkAllWhenApproximationErrorAbove40Percent) {
  MoveLimitInput in = Baseline();
  in.max_approximation_error = 0.41;
  in.move_limits = Eigen::Vector2d(0.2, 0.4);
  in.dx_new = Eigen::Vector2d(0.1, 0.1);
  in.dx_old = Eigen::Vector2d(0.1, 0.1);
  in.on_move_limit = {true, false};
  in.on_bound = {false, true};
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_FALSE(d.accept);
  EXPECT_NE(d.rejection_reason.find("approximation error"), std::string::npos);
  EXPECT_NEAR(d.move_limits_next[0], 0.15, kTol);
  EXPECT_NEAR(d.move_limits_next[1], 0.3, kTol);
  EXPECT_EQ(d.branches[1], MoveLimitBranch::kRejected);
}

TEST(MoveLimits, RejectWhenViolationAbove10PercentWithFeasibleLp) {
  MoveLimitInput in = Baseline();
  in.max_violation = 0.11;
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_FALSE(d.accept);
  EXPECT_NE(d.rejection_reason.find("violation"), std::string::npos);
  EXPECT_NEAR(d.move_limits_next[0], 0.15, kTol);
}

TEST(MoveLimits, AcceptLargeViolationWhenLpWasInfeasible) {
  // An infeasible LP is a restoration step: a violated trial is expected.
  MoveLimitInput in = Baseline();
  in.max_violation = 0.5;
  in.lp_feasible = false;
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_TRUE(d.accept);
}

TEST(MoveLimits, RejectWhenTrialAnalysisFailed) {
  MoveLimitInput in = Baseline();
  in.trial_failed = true;
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_FALSE(d.accept);
  EXPECT_NEAR(d.move_limits_next[0], 0.15, kTol);
}

TEST(MoveLimits, ShrinkWhenDesignOscillates) {
  MoveLimitInput in = Baseline();
  in.dx_new[0] = -0.1;               // direction reversed
  in.objective_trial = 9.9;          // 1 % change < 2 %
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_TRUE(d.accept);
  EXPECT_EQ(d.branches[0], MoveLimitBranch::kOscillation);
  EXPECT_NEAR(d.move_limits_next[0], 0.1, kTol);
}

TEST(MoveLimits, ShrinkWhenDesignAndObjectiveChangeAlternate) {
  MoveLimitInput in = Baseline();
  in.dx_new[0] = -0.1;
  in.objective_trial = 8.0;             // large change, but
  in.previous_objective_change = +0.5;  // F went up last cycle and down now
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_EQ(d.branches[0], MoveLimitBranch::kOscillation);
  EXPECT_NEAR(d.move_limits_next[0], 0.1, kTol);
}

TEST(MoveLimits, NoOscillationWhenDesignReversesWhileObjectiveFallsSteadily) {
  MoveLimitInput in = Baseline();
  in.dx_new[0] = -0.1;
  in.objective_trial = 8.0;  // 20 % better, same sign as last time
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_EQ(d.branches[0], MoveLimitBranch::kUnchanged);
}

TEST(MoveLimits, NoOscillationInTheFirstCycle) {
  MoveLimitInput in = Baseline();
  in.dx_old.resize(0);
  in.previous_objective_change.reset();
  in.objective_trial = 9.99;
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_EQ(d.branches[0], MoveLimitBranch::kUnchanged);
}

TEST(MoveLimits, NoOscillationShrinkWithInfeasibleLp) {
  MoveLimitInput in = Baseline();
  in.dx_new[0] = -0.1;
  in.objective_trial = 9.99;
  in.lp_feasible = false;
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_NE(d.branches[0], MoveLimitBranch::kOscillation);
}

TEST(MoveLimits, ShrinkWhenObjectiveGetsWorseWithFeasibleLp) {
  MoveLimitInput in = Baseline();
  in.objective_trial = 10.5;
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_TRUE(d.accept);
  EXPECT_EQ(d.branches[0], MoveLimitBranch::kNoImprovement);
  EXPECT_NEAR(d.move_limits_next[0], 0.15, kTol);
}

TEST(MoveLimits, WidenOnMoveLimitWhenApproximationIsGood) {
  MoveLimitInput in = Baseline();
  in.max_approximation_error = 0.05;
  in.max_violation = 0.01;
  in.on_move_limit = {true};
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_EQ(d.branches[0], MoveLimitBranch::kOnMoveLimitWiden);
  EXPECT_NEAR(d.move_limits_next[0], 0.2 * 4.0 / 3.0, kTol);
}

TEST(MoveLimits, WidenOnMoveLimitWhenLpInfeasibleDespiteViolation) {
  MoveLimitInput in = Baseline();
  in.max_approximation_error = 0.05;
  in.max_violation = 0.3;
  in.lp_feasible = false;
  in.on_move_limit = {true};
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_EQ(d.branches[0], MoveLimitBranch::kOnMoveLimitWiden);
}

TEST(MoveLimits, NarrowOnMoveLimitWhenApproximationIsPoor) {
  MoveLimitInput in = Baseline();
  in.max_approximation_error = 0.3;
  in.on_move_limit = {true};
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_EQ(d.branches[0], MoveLimitBranch::kOnMoveLimitNarrow);
  EXPECT_NEAR(d.move_limits_next[0], 0.15, kTol);
}

TEST(MoveLimits, NarrowOnMoveLimitWhenViolationAbove7point5Percent) {
  MoveLimitInput in = Baseline();
  in.max_approximation_error = 0.05;
  in.max_violation = 0.08;
  in.on_move_limit = {true};
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_EQ(d.branches[0], MoveLimitBranch::kOnMoveLimitNarrow);
}

TEST(MoveLimits, KeepOnMoveLimitBetweenGoodAndPoor) {
  MoveLimitInput in = Baseline();
  in.on_move_limit = {true};
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_EQ(d.branches[0], MoveLimitBranch::kOnMoveLimitKeep);
  EXPECT_NEAR(d.move_limits_next[0], 0.2, kTol);
}

TEST(MoveLimits, KeepWhenOnMoveLimitAndOnBound) {
  MoveLimitInput in = Baseline();
  in.max_approximation_error = 0.3;
  in.on_move_limit = {true};
  in.on_bound = {true};
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_EQ(d.branches[0], MoveLimitBranch::kUnchanged);
  EXPECT_NEAR(d.move_limits_next[0], 0.2, kTol);
}

TEST(MoveLimits, NarrowInsideTheBoxWhenApproximationIsPoor) {
  MoveLimitInput in = Baseline();
  in.max_approximation_error = 0.3;
  const MoveLimitDecision d = ApplyMoveLimitStrategy(SlpOptions{}, in);
  EXPECT_EQ(d.branches[0], MoveLimitBranch::kPoorApproximationNarrow);
  EXPECT_NEAR(d.move_limits_next[0], 0.15, kTol);
}

TEST(MoveLimits, ClampedToMinAndMax) {
  SlpOptions o;
  o.min_move_limit = 0.19;
  MoveLimitInput in = Baseline();
  in.max_approximation_error = 0.5;
  EXPECT_NEAR(ApplyMoveLimitStrategy(o, in).move_limits_next[0], 0.19, kTol);
  o.max_move_limit = 0.21;
  in = Baseline();
  in.max_approximation_error = 0.0;
  in.on_move_limit = {true};
  EXPECT_NEAR(ApplyMoveLimitStrategy(o, in).move_limits_next[0], 0.21, kTol);
}

TEST(MoveLimits, RelativeObjectiveChangeUsesFloorNearZero) {
  EXPECT_NEAR(RelativeObjectiveChange(2.0, 1.0, 1e-10), 0.5, kTol);
  EXPECT_NEAR(RelativeObjectiveChange(0.0, 1e-12, 1e-10), 0.01, 1e-12);
}

}  // namespace
}  // namespace mbopt::slp
