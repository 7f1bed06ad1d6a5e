// The SLP core with gradients that come with the analyses
// (SlpOptions::analyses_provide_gradients), on a small closed-form problem:
// minimize (x0 - 1)^2 + (x1 - 2)^2 subject to x0 + x1 <= 2, optimum (0.5, 1.5).
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "server/lp/make_clp_lp_solver.h"
#include "server/slp/slp_optimizer.h"

namespace mbopt::slp {
namespace {

constexpr double kOptimumTolerance = 0.02;  // scaled x; convergence test is 0.5 % in F

ProblemSpec Problem() {
  ProblemSpec p;
  p.variable_names = {"x0", "x1"};
  p.lower = Eigen::Vector2d(-5, -5);
  p.upper = Eigen::Vector2d(5, 5);
  p.initial = Eigen::Vector2d(3, 3);
  p.constraint_names = {"sum"};
  p.constraint_limits = Eigen::VectorXd::Constant(1, 2.0);
  p.constraint_scales = Eigen::VectorXd::Constant(1, 2.0);
  return p;
}

AnalysisResult Answer(const AnalysisRequest& r, bool with_gradients) {
  AnalysisResult a;
  a.request_id = r.id;
  const Eigen::VectorXd& x = r.x;
  a.objective_terms = Eigen::VectorXd::Constant(1, std::pow(x[0] - 1, 2) + std::pow(x[1] - 2, 2));
  a.constraint_values = Eigen::VectorXd::Constant(1, x[0] + x[1]);
  if (with_gradients) {
    a.objective_gradients = Eigen::MatrixXd(1, 2);
    a.objective_gradients << 2 * (x[0] - 1), 2 * (x[1] - 2);
    a.constraint_gradients = Eigen::MatrixXd::Ones(1, 2);
  } else {
    a.objective_gradients = Eigen::MatrixXd::Constant(1, 2, std::numeric_limits<double>::quiet_NaN());
    a.constraint_gradients = Eigen::MatrixXd::Ones(1, 2);
  }
  return a;
}

SlpOptions WithGradients() {
  SlpOptions o;
  o.analyses_provide_gradients = true;
  return o;
}

TEST(SlpWithAnalysisGradients, RequestsOnlyDesignPointsWithGradientsAndConverges) {
  SlpOptimizer opt(Problem(), WithGradients(), lp::MakeClpLpSolver());
  int rounds = 0;
  while (opt.state() == RunState::kRunning && rounds++ < 1000) {
    for (const AnalysisRequest& r : opt.PendingRequests()) {
      EXPECT_NE(r.purpose, RequestPurpose::kPerturbation);
      EXPECT_TRUE(r.want_gradients);
      ASSERT_TRUE(opt.SubmitResult(Answer(r, true)).ok());
    }
  }
  EXPECT_EQ(opt.state(), RunState::kConverged) << opt.end_reason();
  EXPECT_NEAR(opt.current_design()[0], 0.5, kOptimumTolerance);
  EXPECT_NEAR(opt.current_design()[1], 1.5, kOptimumTolerance);
}

TEST(SlpWithAnalysisGradients, FallsBackToFiniteDifferencesWhenGradientsAreNotFinite) {
  SlpOptimizer opt(Problem(), WithGradients(), lp::MakeClpLpSolver());
  bool perturbed = false;
  int rounds = 0;
  while (opt.state() == RunState::kRunning && rounds++ < 1000) {
    for (const AnalysisRequest& r : opt.PendingRequests()) {
      perturbed = perturbed || r.purpose == RequestPurpose::kPerturbation;
      ASSERT_TRUE(opt.SubmitResult(Answer(r, false)).ok());
    }
  }
  EXPECT_TRUE(perturbed);
  EXPECT_EQ(opt.state(), RunState::kConverged) << opt.end_reason();
  EXPECT_NEAR(opt.current_design()[0], 0.5, kOptimumTolerance);
  EXPECT_NEAR(opt.current_design()[1], 1.5, kOptimumTolerance);
}

TEST(SlpWithAnalysisGradients, ReplayingTheResultsRebuildsTheRunBitForBit) {
  SlpOptimizer first(Problem(), WithGradients(), lp::MakeClpLpSolver());
  std::vector<AnalysisResult> log;
  int rounds = 0;
  while (first.state() == RunState::kRunning && rounds++ < 1000) {
    for (const AnalysisRequest& r : first.PendingRequests()) {
      log.push_back(Answer(r, true));
      ASSERT_TRUE(first.SubmitResult(log.back()).ok());
    }
  }
  SlpOptimizer replay(Problem(), WithGradients(), lp::MakeClpLpSolver());
  for (const AnalysisResult& r : log) ASSERT_TRUE(replay.SubmitResult(r).ok());
  EXPECT_EQ(replay.state(), first.state());
  EXPECT_EQ(replay.current_design(), first.current_design());  // bit identity is the point
  EXPECT_EQ(replay.analyses_used(), first.analyses_used());
}

TEST(SlpWithAnalysisGradients, RejectsGradientsOfTheWrongShape) {
  SlpOptimizer opt(Problem(), WithGradients(), lp::MakeClpLpSolver());
  AnalysisResult a = Answer(opt.PendingRequests().front(), true);
  a.objective_gradients = Eigen::MatrixXd::Ones(1, 3);
  EXPECT_EQ(opt.SubmitResult(a).code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace mbopt::slp
