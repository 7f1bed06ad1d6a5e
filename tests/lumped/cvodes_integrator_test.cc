// CvodesIntegrator against closed-form solutions, and its failure paths:
// every failure is a status with a reason, never a crash or a message on
// stderr.
#include "worker/sundials/cvodes_integrator.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "tests/testing/fake_clock.h"
#include "worker/sundials/integrator_failure.h"

namespace mbopt::sundials {
namespace {

using ::testing::HasSubstr;

// rtol 1e-10 on a smooth scalar problem: the global error stays within a
// few hundred times rtol.
constexpr double kClosedFormTolerance = 1e-7;

CvodesIntegrator::RhsFunction Decay() {
  return [](double, const double* y, double* ydot) {
    ydot[0] = -y[0];
    return 0;
  };
}

CvodesOptions Tight() {
  CvodesOptions o;
  o.relative_tolerance = 1e-10;
  o.absolute_tolerance = 1e-12;
  return o;
}

TEST(CvodesIntegrator, ExponentialDecayMatchesClosedFormWithBdf) {
  auto integrator =
      CvodesIntegrator::Create(1, Decay(), nullptr, Tight(), 0.0, Eigen::VectorXd::Ones(1));
  ASSERT_TRUE(integrator.ok()) << integrator.status();
  Eigen::VectorXd y;
  for (double t : {0.0, 0.5, 1.0, 3.0}) {
    ASSERT_TRUE((*integrator)->IntegrateTo(t, &y).ok());
    EXPECT_NEAR(y[0], std::exp(-t), kClosedFormTolerance) << "t = " << t;
  }
  EXPECT_GT((*integrator)->counters().steps, 0);
  EXPECT_GT((*integrator)->counters().rhs_evaluations, 0);
}

TEST(CvodesIntegrator, HarmonicOscillatorMatchesClosedFormWithAdamsAndAnalyticJacobian) {
  auto rhs = [](double, const double* y, double* ydot) {
    ydot[0] = y[1];
    ydot[1] = -4.0 * y[0];
    return 0;
  };
  auto jac = [](double, const double*, const double*, double* j) {
    j[2] = 1.0;   // (0, 1), column-major
    j[1] = -4.0;  // (1, 0)
    return 0;
  };
  for (auto iteration :
       {CvodesOptions::Iteration::kNewton, CvodesOptions::Iteration::kFixedPoint}) {
    CvodesOptions o = Tight();
    o.method = CvodesOptions::Method::kAdams;
    o.iteration = iteration;
    Eigen::VectorXd y0(2);
    y0 << 1.0, 0.0;
    auto integrator = CvodesIntegrator::Create(2, rhs, jac, o, 0.0, y0);
    ASSERT_TRUE(integrator.ok()) << integrator.status();
    Eigen::VectorXd y;
    ASSERT_TRUE((*integrator)->IntegrateTo(2.0, &y).ok());
    EXPECT_NEAR(y[0], std::cos(4.0), kClosedFormTolerance);
    EXPECT_NEAR(y[1], -2.0 * std::sin(4.0), kClosedFormTolerance);
    if (iteration == CvodesOptions::Iteration::kNewton) {
      EXPECT_GT((*integrator)->counters().jacobian_evaluations, 0);
    }
  }
}

// A damped oscillator q'' + 2 zeta w q' + w^2 q = 0 through a caller's
// Newton solver that uses the second-order structure: (I - gamma J) x = b
// reduces to the scalar (1 + gamma c + gamma^2 k) x_v = b_v - gamma k b_u.
TEST(CvodesIntegrator, CallerNewtonSolverMatchesClosedFormDampedOscillator) {
  constexpr double kOmega = 3.0, kZeta = 0.1;
  constexpr double k = kOmega * kOmega, c = 2.0 * kZeta * kOmega;
  auto rhs = [](double, const double* y, double* ydot) {
    ydot[0] = y[1];
    ydot[1] = -k * y[0] - c * y[1];
    return 0;
  };
  int calls = 0;
  auto newton = [&calls](double, double gamma, double* bx, bool* refactored) {
    ++calls;
    *refactored = true;
    bx[1] = (bx[1] - gamma * k * bx[0]) / (1.0 + gamma * c + gamma * gamma * k);
    bx[0] += gamma * bx[1];
    return 0;
  };
  Eigen::VectorXd y0(2);
  y0 << 1.0, 0.0;
  for (auto refresh : {CvodesIntegrator::NewtonRefresh::kEveryIteration,
                       CvodesIntegrator::NewtonRefresh::kCvodesSetups}) {
    calls = 0;
    auto integrator =
        CvodesIntegrator::CreateWithNewtonSolver(2, rhs, newton, refresh, Tight(), 0.0, y0);
    ASSERT_TRUE(integrator.ok()) << integrator.status();
    Eigen::VectorXd y;
    constexpr double kT = 2.0;
    ASSERT_TRUE((*integrator)->IntegrateTo(kT, &y).ok());
    const double wd = kOmega * std::sqrt(1.0 - kZeta * kZeta);
    const double decay = std::exp(-kZeta * kOmega * kT);
    const double q = decay * (std::cos(wd * kT) + kZeta * kOmega / wd * std::sin(wd * kT));
    const double v = -decay * kOmega * kOmega / wd * std::sin(wd * kT);
    EXPECT_NEAR(y[0], q, kClosedFormTolerance);
    EXPECT_NEAR(y[1], v, kClosedFormTolerance);
    EXPECT_GT(calls, 0);
    EXPECT_EQ((*integrator)->counters().jacobian_evaluations, calls);
  }
}

TEST(CvodesIntegrator, CallerNewtonSolverFailureIsAStatus) {
  auto newton = [](double, double, double*, bool*) { return -3; };
  auto integrator = CvodesIntegrator::CreateWithNewtonSolver(
      1, Decay(), newton, CvodesIntegrator::NewtonRefresh::kCvodesSetups, Tight(), 0.0,
      Eigen::VectorXd::Ones(1));
  ASSERT_TRUE(integrator.ok()) << integrator.status();
  Eigen::VectorXd y;
  const absl::Status s = (*integrator)->IntegrateTo(1.0, &y);
  EXPECT_FALSE(s.ok());
  EXPECT_THAT(std::string(s.message()), HasSubstr("Newton solver"));
}

TEST(CvodesIntegrator, StopsExactlyAtStopTimeAndRestartsThere) {
  // y' = 0 before t = 1 and 1 after: a kink the integrator must not step across.
  auto rhs = [](double t, const double*, double* ydot) {
    ydot[0] = t < 1.0 ? 0.0 : 1.0;
    return 0;
  };
  auto integrator =
      CvodesIntegrator::Create(1, rhs, nullptr, Tight(), 0.0, Eigen::VectorXd::Zero(1));
  ASSERT_TRUE(integrator.ok());
  CvodesIntegrator& i = **integrator;
  ASSERT_TRUE(i.SetStopTime(1.0).ok());
  Eigen::VectorXd y;
  ASSERT_TRUE(i.IntegrateTo(0.5, &y).ok());
  ASSERT_TRUE(i.IntegrateTo(1.0, &y).ok());
  EXPECT_DOUBLE_EQ(i.current_time(), 1.0);
  ASSERT_TRUE(i.Restart(1.0, y).ok());
  // An output instant one ulp after the restart is answered, not refused.
  ASSERT_TRUE(i.IntegrateTo(std::nextafter(1.0, 2.0), &y).ok());
  ASSERT_TRUE(i.IntegrateTo(2.5, &y).ok());
  EXPECT_NEAR(y[0], 1.5, kClosedFormTolerance);
  EXPECT_EQ(i.counters().restarts, 1);
}

// y' = rhs from y(0) = 0 to t = 1 with the default options: how the
// integration ended.
absl::Status IntegrateScalarToOne(const CvodesIntegrator::RhsFunction& rhs) {
  auto integrator =
      CvodesIntegrator::Create(1, rhs, nullptr, CvodesOptions(), 0.0, Eigen::VectorXd::Zero(1));
  if (!integrator.ok()) return integrator.status();
  Eigen::VectorXd y;
  return (*integrator)->IntegrateTo(1.0, &y);
}

TEST(CvodesIntegrator, ThrowingRhsIsAFailedIntegrationWithReason) {
  auto rhs = [](double t, const double*, double* ydot) -> int {
    if (t > 0.1) throw std::runtime_error("model exploded");
    ydot[0] = 1.0;
    return 0;
  };
  const absl::Status s = IntegrateScalarToOne(rhs);
  EXPECT_EQ(s.code(), absl::StatusCode::kAborted);
  EXPECT_THAT(std::string(s.message()), HasSubstr("model exploded"));
}

TEST(CvodesIntegrator, NonFiniteRhsIsAFailedIntegration) {
  auto rhs = [](double t, const double*, double* ydot) {
    ydot[0] = t > 0.2 ? std::numeric_limits<double>::quiet_NaN() : 1.0;
    return 0;
  };
  const absl::Status s = IntegrateScalarToOne(rhs);
  EXPECT_EQ(s.code(), absl::StatusCode::kAborted);
  EXPECT_THAT(std::string(s.message()), HasSubstr("not finite"));
}

TEST(CvodesIntegrator, StepBudgetIsEnforcedAcrossCalls) {
  CvodesOptions o = Tight();
  o.max_steps = 5;
  auto integrator = CvodesIntegrator::Create(1, Decay(), nullptr, o, 0.0, Eigen::VectorXd::Ones(1));
  ASSERT_TRUE(integrator.ok());
  Eigen::VectorXd y;
  const absl::Status s = (*integrator)->IntegrateTo(10.0, &y);
  EXPECT_EQ(s.code(), absl::StatusCode::kAborted);
  EXPECT_THAT(std::string(s.message()), HasSubstr("step budget"));
  EXPECT_LE((*integrator)->counters().steps, 5);
}

// The budget's clock moves 1 s per reading: the 5 s deadline passes at a
// known right-hand side, however fast the machine.
TEST(CvodesIntegrator, BudgetDeadlineIsDeadlineExceeded) {
  const mbopt::testing::SteppingClock clock(1.0);
  const budget::AnalysisBudget budget = budget::AnalysisBudget(clock.AsClock(), nullptr).ForAnalysis(5.0, 0);
  CvodesOptions o;
  o.budget = &budget;
  auto integrator = CvodesIntegrator::Create(1, Decay(), nullptr, o, 0.0, Eigen::VectorXd::Ones(1));
  ASSERT_TRUE(integrator.ok());
  Eigen::VectorXd y;
  const absl::Status s = (*integrator)->IntegrateTo(100.0, &y);
  EXPECT_EQ(s.code(), absl::StatusCode::kDeadlineExceeded) << s;
  EXPECT_THAT(std::string(s.message()), HasSubstr("wall-time limit of 5 s"));
  EXPECT_EQ(IntegratorFailure(s, "x").kind, spec::FailureKind::kTimeLimit);
}

TEST(CvodesIntegrator, BudgetCancelIsCancelled) {
  const mbopt::testing::CancelAfter cancel(3);
  const budget::AnalysisBudget budget(nullptr, cancel.AsFlag());
  CvodesOptions o;
  o.budget = &budget;
  auto integrator = CvodesIntegrator::Create(1, Decay(), nullptr, o, 0.0, Eigen::VectorXd::Ones(1));
  ASSERT_TRUE(integrator.ok());
  Eigen::VectorXd y;
  const absl::Status s = (*integrator)->IntegrateTo(100.0, &y);
  EXPECT_EQ(s.code(), absl::StatusCode::kCancelled) << s;
  EXPECT_EQ(IntegratorFailure(s, "x").kind, spec::FailureKind::kCancelled);
  EXPECT_LE((*integrator)->counters().rhs_evaluations, 3);
}

TEST(CvodesIntegrator, InvalidOptionsAndInputsAreRejected) {
  CvodesOptions o;
  o.relative_tolerance = -1;
  EXPECT_EQ(CvodesIntegrator::Create(1, Decay(), nullptr, o, 0.0, Eigen::VectorXd::Ones(1))
                .status()
                .code(),
            absl::StatusCode::kInvalidArgument);
  o = CvodesOptions();
  o.absolute_tolerances = Eigen::VectorXd::Ones(3);
  EXPECT_EQ(CvodesIntegrator::Create(1, Decay(), nullptr, o, 0.0, Eigen::VectorXd::Ones(1))
                .status()
                .code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(
      CvodesIntegrator::Create(2, Decay(), nullptr, CvodesOptions(), 0.0, Eigen::VectorXd::Ones(1))
          .status()
          .code(),
      absl::StatusCode::kInvalidArgument);
  auto integrator =
      CvodesIntegrator::Create(1, Decay(), nullptr, CvodesOptions(), 1.0, Eigen::VectorXd::Ones(1));
  ASSERT_TRUE(integrator.ok());
  Eigen::VectorXd y;
  EXPECT_EQ((*integrator)->IntegrateTo(0.5, &y).code(), absl::StatusCode::kInvalidArgument);
}

TEST(CvodesIntegrator, PerStateAbsoluteTolerancesAreAccepted) {
  CvodesOptions o = Tight();
  o.absolute_tolerances = Eigen::VectorXd::Constant(1, 1e-12);
  auto integrator = CvodesIntegrator::Create(1, Decay(), nullptr, o, 0.0, Eigen::VectorXd::Ones(1));
  ASSERT_TRUE(integrator.ok()) << integrator.status();
  Eigen::VectorXd y;
  ASSERT_TRUE((*integrator)->IntegrateTo(1.0, &y).ok());
  EXPECT_NEAR(y[0], std::exp(-1.0), kClosedFormTolerance);
}

}  // namespace
}  // namespace mbopt::sundials
