// Model Exchange FMUs integrated with CVODES, checked against closed forms.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "tests/fmu/closed_forms.h"
#include "tests/testing/fake_clock.h"
#include "worker/fmu/fmu.h"
#include "worker/fmu/simulation.h"

namespace mbopt::fmu {
namespace {

using testing::BouncingBall;
using testing::DampedOscillator;
using testing::Grid;
using testing::StepResponse;
using testing::TestFmu;

Fmu OpenModelExchange(const std::string& name) {
  auto fmu = Fmu::Open(TestFmu(name), Interface::kModelExchange);
  EXPECT_TRUE(fmu.ok()) << fmu.status();
  return *std::move(fmu);
}

// CVODES at rtol 1e-10, atol 1e-12 keeps the global error of these smooth,
// short runs well below 1e-7 of the state's scale.
RunOptions Tight(std::vector<std::pair<std::string, double>> parameters, std::vector<std::string> outputs,
                 std::vector<double> times) {
  RunOptions options;
  options.parameters = std::move(parameters);
  options.outputs = std::move(outputs);
  options.output_times_s = std::move(times);
  options.relative_tolerance = 1e-10;
  options.absolute_tolerance = 1e-12;
  return options;
}

TEST(FmuModelExchange, DampedOscillatorFollowsItsClosedFormWithParametersSetByName) {
  const Fmu fmu = OpenModelExchange("damped_oscillator");
  const DampedOscillator exact{2.0, 0.6, 18.0, 0.2};  // none of them the FMU's start values
  const std::vector<double> times = Grid(0.0, 10.0, 400);
  auto result = Simulate(fmu, Tight({{"mass_kg", 2.0}, {"damping_n_s_per_m", 0.6}, {"stiffness_n_per_m", 18.0},
                                {"x0_m", 0.2}},
                               {"x_m", "spring_force_n"}, times));
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->outcome, RunOutcome::kOk) << result->reason;
  constexpr double kToleranceM = 1e-8;  // of a 0.2 m amplitude
  for (std::size_t i = 0; i < times.size(); ++i) {
    EXPECT_NEAR(result->values[0][i], exact.X(times[i]), kToleranceM) << "t = " << times[i];
    EXPECT_NEAR(result->values[1][i], -18.0 * exact.X(times[i]), 18.0 * kToleranceM) << "t = " << times[i];
  }
  EXPECT_TRUE(result->state_event_times_s.empty());
  EXPECT_TRUE(result->time_event_times_s.empty());
  EXPECT_GT(result->integrator_steps, 0);
}

TEST(FmuModelExchange, VanDerPolReachesItsLimitCycle) {
  const Fmu fmu = OpenModelExchange("van_der_pol");
  const std::vector<double> times = Grid(0.0, 40.0, 40000);
  auto result = Simulate(fmu, Tight({{"mu", 1.0}}, {"x0"}, times));
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->outcome, RunOutcome::kOk) << result->reason;
  const std::vector<double>& x = result->values[0];
  // After 20 s the transient from x = 2 has died out (to far below 1e-6).
  double amplitude = 0.0;
  std::vector<double> upward_crossings_s;
  for (std::size_t i = 1; i < times.size(); ++i) {
    if (times[i] < 20.0) continue;
    amplitude = std::max(amplitude, std::abs(x[i]));
    if (x[i - 1] < 0.0 && x[i] >= 0.0) {
      upward_crossings_s.push_back(times[i - 1] + (times[i] - times[i - 1]) * -x[i - 1] / (x[i] - x[i - 1]));
    }
  }
  // The 1 ms grid finds the peak to x'' dt^2 / 2 ~ 1e-6 and a crossing to
  // the secant's error, ~ x'' dt^2 / |x'| ~ 1e-6 s.
  EXPECT_NEAR(amplitude, testing::kVanDerPolAmplitudeMu1, 1e-5);
  ASSERT_GE(upward_crossings_s.size(), 2u);
  const double period_s = (upward_crossings_s.back() - upward_crossings_s.front()) /
                          static_cast<double>(upward_crossings_s.size() - 1);
  EXPECT_NEAR(period_s, testing::kVanDerPolPeriodMu1_s, 1e-5);
}

TEST(FmuModelExchange, BouncingBallImpactsAtTheAnalyticTimes) {
  const Fmu fmu = OpenModelExchange("bouncing_ball");
  const BouncingBall exact{1.5, 9.81, 0.7};
  const std::vector<double> times = Grid(0.0, 2.5, 250);
  auto result = Simulate(fmu, Tight({{"h0_m", 1.5}, {"e", 0.7}}, {"h_m"}, times));
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->outcome, RunOutcome::kOk) << result->reason;
  const std::vector<double> impacts = exact.ImpactTimes(4);
  ASSERT_LT(impacts[3], 2.5);
  ASSERT_GE(result->state_event_times_s.size(), 4u);
  constexpr double kImpactToleranceS = 1e-6;
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(result->state_event_times_s[k], impacts[k], kImpactToleranceS) << "impact " << k;
  }
  // Each impact is found once: no spurious event when the ball leaves the floor.
  const auto impacts_by_end = exact.ImpactTimes(20);
  const auto expected_count = std::count_if(impacts_by_end.begin(), impacts_by_end.end(), [](double t) { return t <= 2.5; });
  EXPECT_EQ(static_cast<long>(result->state_event_times_s.size()), expected_count);
  for (std::size_t i = 0; i < times.size(); ++i) {
    EXPECT_NEAR(result->values[0][i], exact.Height(times[i]), 1e-6) << "t = " << times[i];
  }
}

TEST(FmuModelExchange, TimeEventHappensExactlyWhenTheFmuAsks) {
  const Fmu fmu = OpenModelExchange("step_response");
  const StepResponse exact{0.25, 0.37};  // t_step between grid points
  const std::vector<double> times = Grid(0.0, 2.0, 100);
  auto result = Simulate(fmu, Tight({{"tau_s", 0.25}, {"t_step_s", 0.37}}, {"y", "u"}, times));
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->outcome, RunOutcome::kOk) << result->reason;
  // Bit-exact: the integrator is stopped at the time the FMU asked for.
  EXPECT_EQ(result->time_event_times_s, std::vector<double>{0.37});
  EXPECT_TRUE(result->state_event_times_s.empty());
  for (std::size_t i = 0; i < times.size(); ++i) {
    EXPECT_NEAR(result->values[0][i], exact.Y(times[i]), 1e-8) << "t = " << times[i];
    EXPECT_EQ(result->values[1][i], times[i] < 0.37 ? 0.0 : 1.0) << "t = " << times[i];
  }
}

TEST(FmuModelExchange, SameRunTwiceIsBitIdentical) {
  const Fmu fmu = OpenModelExchange("bouncing_ball");
  const RunOptions options = Tight({{"e", 0.9}}, {"h_m", "v_m_per_s"}, Grid(0.0, 3.0, 300));
  auto first = Simulate(fmu, options);
  auto second = Simulate(OpenModelExchange("bouncing_ball"), options);
  ASSERT_TRUE(first.ok() && second.ok());
  EXPECT_EQ(first->values, second->values);
  EXPECT_EQ(first->state_event_times_s, second->state_event_times_s);
}

// The budget's clock advances 1 s per reading: the 10 s limit falls after
// ten checks, on any machine.
TEST(FmuModelExchange, WallTimeLimitEndsTheRun) {
  const Fmu fmu = OpenModelExchange("van_der_pol");
  RunOptions options = Tight({}, {"x0"}, Grid(0.0, 40.0, 4000));
  const mbopt::testing::SteppingClock clock(1.0);
  const budget::AnalysisBudget budget =
      budget::AnalysisBudget(clock.AsClock(), nullptr).ForAnalysis(10.0, 0);
  options.budget = &budget;
  auto result = Simulate(fmu, options);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->outcome, RunOutcome::kTimeLimit);
  EXPECT_THAT(result->reason, ::testing::HasSubstr("the wall-time limit of 10 s (integrator.max_wall_seconds) was "
                                                   "reached at t = "));
  EXPECT_EQ(clock.reads(), 12) << "one reading sets the deadline, ten pass it, the eleventh is over";
}

TEST(FmuModelExchange, CancelledRunEndsAtTheNextStep) {
  const Fmu fmu = OpenModelExchange("van_der_pol");
  RunOptions options = Tight({}, {"x0"}, Grid(0.0, 40.0, 4000));
  const mbopt::testing::CancelAfter cancel(5);
  const budget::AnalysisBudget budget(nullptr, cancel.AsFlag());
  options.budget = &budget;
  auto result = Simulate(fmu, options);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->outcome, RunOutcome::kCancelled);
  EXPECT_THAT(result->reason, ::testing::HasSubstr("cancelled at t = "));
  EXPECT_LT(result->integrator_steps, 20);
}

TEST(FmuModelExchange, OutputAtTheStartTimeIsTheInitialValue) {
  const Fmu fmu = OpenModelExchange("damped_oscillator");
  auto result = Simulate(fmu, Tight({{"x0_m", 0.3}}, {"x_m"}, {0.0, 0.0, 0.5}));
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->outcome, RunOutcome::kOk) << result->reason;
  EXPECT_EQ(result->values[0][0], 0.3);
  EXPECT_EQ(result->values[0][1], 0.3);
}

}  // namespace
}  // namespace mbopt::fmu
