// FMI 3.0 FMUs (the test models built with models/model_frame3.c) through
// the same Simulate as FMI 2.0 ones: Model Exchange with CVODES, state
// events, Co-Simulation at the FMU's step, checked against closed forms.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "tests/fmu/closed_forms.h"
#include "worker/fmu/fmu.h"
#include "worker/fmu/simulation.h"

namespace mbopt::fmu {
namespace {

using ::testing::HasSubstr;
using testing::BouncingBall;
using testing::DampedOscillator;
using testing::Grid;
using testing::TestFmu;

Fmu Open(const std::string& name, Interface interface) {
  auto fmu = Fmu::Open(TestFmu(name), interface);
  EXPECT_TRUE(fmu.ok()) << fmu.status();
  return *std::move(fmu);
}

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

TEST(Fmi3, TheArchiveIsReadAsFmi3) {
  const Fmu fmu = Open("damped_oscillator_fmi3", Interface::kModelExchange);
  EXPECT_EQ(fmu.description().fmi_major_version, 3);
  EXPECT_EQ(fmu.description().guid, "{mbopt-test-damped-oscillator-1}");
  EXPECT_EQ(fmu.description().state_indices.size(), 2u);
}

TEST(Fmi3ModelExchange, DampedOscillatorFollowsItsClosedForm) {
  const Fmu fmu = Open("damped_oscillator_fmi3", Interface::kModelExchange);
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
  EXPECT_GT(result->integrator_steps, 0);
}

TEST(Fmi3ModelExchange, BouncingBallImpactsAtTheAnalyticTimes) {
  const Fmu fmu = Open("bouncing_ball_fmi3", Interface::kModelExchange);
  ASSERT_EQ(fmu.description().number_of_event_indicators, 1);
  const BouncingBall exact{1.5, 9.81, 0.7};
  const std::vector<double> times = Grid(0.0, 2.5, 250);
  auto result = Simulate(fmu, Tight({{"h0_m", 1.5}, {"e", 0.7}}, {"h_m"}, times));
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->outcome, RunOutcome::kOk) << result->reason;
  const std::vector<double> impacts_by_end = exact.ImpactTimes(20);
  const auto expected_count =
      std::count_if(impacts_by_end.begin(), impacts_by_end.end(), [](double t) { return t <= 2.5; });
  ASSERT_GE(expected_count, 4);
  ASSERT_EQ(static_cast<long>(result->state_event_times_s.size()), expected_count);
  for (long k = 0; k < expected_count; ++k) {
    EXPECT_NEAR(result->state_event_times_s[k], impacts_by_end[k], 1e-6) << "impact " << k;
  }
  for (std::size_t i = 0; i < times.size(); ++i) {
    EXPECT_NEAR(result->values[0][i], exact.Height(times[i]), 1e-6) << "t = " << times[i];
  }
}

TEST(Fmi3ModelExchange, GivesTheSameResultsAsTheFmi2BuildOfTheSameModel) {
  const RunOptions options = Tight({{"e", 0.9}}, {"h_m", "v_m_per_s"}, Grid(0.0, 3.0, 300));
  auto fmi3 = Simulate(Open("bouncing_ball_fmi3", Interface::kModelExchange), options);
  auto fmi2 = Simulate(Open("bouncing_ball", Interface::kModelExchange), options);
  ASSERT_TRUE(fmi3.ok() && fmi2.ok());
  ASSERT_EQ(fmi3->outcome, RunOutcome::kOk) << fmi3->reason;
  // One driver for both versions: the same model integrates bit for bit alike.
  EXPECT_EQ(fmi3->values, fmi2->values);
  EXPECT_EQ(fmi3->state_event_times_s, fmi2->state_event_times_s);
}

TEST(Fmi3ModelExchange, AModelErrorNamesTheFmi3CallAndTheFmusMessage) {
  const Fmu fmu = Open("damped_oscillator_fmi3", Interface::kModelExchange);
  auto result = Simulate(fmu, Tight({{"mass_kg", 0.0}}, {"x_m"}, {0.0, 1.0}));
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->outcome, RunOutcome::kModelError);
  EXPECT_THAT(result->reason, HasSubstr("fmi3ExitInitializationMode returned fmi3Error at t = 0 s"));
  EXPECT_THAT(result->reason, HasSubstr("fmi3Error [model]: mass_kg must be > 0, got 0"));
}

TEST(Fmi3CoSimulation, OscillatorAtItsDefaultStepFollowsItsClosedForm) {
  const Fmu fmu = Open("damped_oscillator_fmi3", Interface::kCoSimulation);
  const DampedOscillator exact{1.0, 0.4, 9.0, 0.1};
  const std::vector<double> times = Grid(0.0, 5.0, 50);  // every 0.1 s: 10 steps of 0.01 s
  RunOptions options;
  options.parameters = {{"stiffness_n_per_m", 9.0}};
  options.outputs = {"x_m"};
  options.output_times_s = times;
  auto result = Simulate(fmu, options);
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->outcome, RunOutcome::kOk) << result->reason;
  EXPECT_EQ(result->integrator_steps, 500);
  for (std::size_t i = 0; i < times.size(); ++i) {
    EXPECT_NEAR(result->values[0][i], exact.X(times[i]), 1e-9) << "t = " << times[i];
  }
}

TEST(Fmi3CoSimulation, AnFmuWithoutCoSimulationIsRefusedByName) {
  auto fmu = Fmu::Open(TestFmu("bouncing_ball_fmi3"), Interface::kCoSimulation);
  ASSERT_FALSE(fmu.ok());
  EXPECT_THAT(fmu.status().message(), HasSubstr("the FMU offers no Co-Simulation"));
}

}  // namespace
}  // namespace mbopt::fmu
