// The finite-difference step rule and derivative quotients.
#include "server/slp/finite_difference.h"

#include <gtest/gtest.h>

namespace mbopt::slp {
namespace {

constexpr double kTol = 1e-15;  // steps are products of exact-ish decimals

TEST(FiniteDifference, StepIsRelativeWithARangeFloor) {
  const SlpOptions o;  // relative step 1e-4, floor 1 % of the range
  EXPECT_NEAR(NominalStep(5.0, 0.0, 10.0, o), 5e-4, kTol);
  EXPECT_NEAR(NominalStep(0.0, -10.0, 10.0, o), 1e-4 * 0.2, kTol);
}

TEST(FiniteDifference, ForwardStepGoesBackwardsAtTheUpperBound) {
  const SlpOptions o;
  EXPECT_EQ(PlanSteps(1.0, 0.0, 2.0, o), std::vector<double>{1e-4});
  const std::vector<double> at_upper = PlanSteps(2.0, 0.0, 2.0, o);
  ASSERT_EQ(at_upper.size(), 1u);
  EXPECT_NEAR(at_upper[0], -2e-4, kTol);
}

TEST(FiniteDifference, CentralStepsShrinkToFitOrFallBackToOneSide) {
  SlpOptions o;
  o.finite_difference = FiniteDifferenceScheme::kCentral;
  const std::vector<double> inside = PlanSteps(1.0, 0.0, 2.0, o);
  ASSERT_EQ(inside.size(), 2u);
  EXPECT_NEAR(inside[0], 1e-4, kTol);
  EXPECT_NEAR(inside[1], -1e-4, kTol);
  // 0.7e-4 of room below: shrink both sides to 0.7e-4.
  const std::vector<double> near = PlanSteps(1.0, 1.0 - 0.7e-4, 2.0, o);
  ASSERT_EQ(near.size(), 2u);
  EXPECT_NEAR(near[1], -0.7e-4, 1e-12);
  // At the lower bound: one forward step.
  const std::vector<double> at = PlanSteps(0.0, 0.0, 2.0, o);
  ASSERT_EQ(at.size(), 1u);
  EXPECT_GT(at[0], 0.0);
}

TEST(FiniteDifference, RetryUsesTheOtherSideOrHalfTheStep) {
  EXPECT_EQ(RetryStep(1.0, 0.0, 2.0, 1e-3), -1e-3);
  EXPECT_EQ(RetryStep(0.0, 0.0, 2.0, 1e-3), 0.5e-3);
}

TEST(FiniteDifference, DerivativeOfAQuadraticIsExactForCentralQuotient) {
  // f(x) = x^2 at x0 = 1: the central quotient is exact, the forward one is
  // off by h.
  const Eigen::VectorXd v0 = Eigen::VectorXd::Constant(1, 1.0);
  const double h = 1e-3;
  const Sample plus{h, Eigen::VectorXd::Constant(1, (1 + h) * (1 + h))};
  const Sample minus{-h, Eigen::VectorXd::Constant(1, (1 - h) * (1 - h))};
  EXPECT_NEAR((*DerivativeFromSamples(v0, {plus, minus}))[0], 2.0, 1e-10);
  EXPECT_NEAR((*DerivativeFromSamples(v0, {plus}))[0], 2.0 + h, 1e-10);
  EXPECT_NEAR((*DerivativeFromSamples(v0, {minus}))[0], 2.0 - h, 1e-10);
  EXPECT_FALSE(DerivativeFromSamples(v0, {}).has_value());
}

}  // namespace
}  // namespace mbopt::slp
