// Co-Simulation FMUs stepped at their communication step.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/fmu/closed_forms.h"
#include "tests/testing/fake_clock.h"
#include "worker/fmu/fmu.h"
#include "worker/fmu/simulation.h"

namespace mbopt::fmu {
namespace {

using ::testing::HasSubstr;
using testing::DampedOscillator;
using testing::Grid;
using testing::StepResponse;
using testing::TestFmu;

Fmu OpenCoSimulation(const std::string& name) {
  auto fmu = Fmu::Open(TestFmu(name), Interface::kCoSimulation);
  EXPECT_TRUE(fmu.ok()) << fmu.status();
  return *std::move(fmu);
}

// The test models integrate each communication step with ten classical
// Runge-Kutta substeps: at a 1 ms substep the oscillator's error is ~1e-12.
constexpr double kRungeKuttaToleranceM = 1e-9;

TEST(FmuCoSimulation, OscillatorAtItsDefaultStepFollowsItsClosedForm) {
  const Fmu fmu = OpenCoSimulation("damped_oscillator");
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
    EXPECT_NEAR(result->values[0][i], exact.X(times[i]), kRungeKuttaToleranceM) << "t = " << times[i];
  }
}

TEST(FmuCoSimulation, TheRunsStepReplacesTheDefault) {
  const Fmu fmu = OpenCoSimulation("damped_oscillator");
  RunOptions options;
  options.outputs = {"x_m"};
  options.output_times_s = Grid(0.0, 1.0, 10);
  options.communication_step_s = 0.02;
  auto result = Simulate(fmu, options);
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->outcome, RunOutcome::kOk) << result->reason;
  EXPECT_EQ(result->integrator_steps, 50);
  EXPECT_NEAR(result->values[0][10], DampedOscillator({1.0, 0.4, 4.0, 0.1}).X(1.0), kRungeKuttaToleranceM);
}

TEST(FmuCoSimulation, TimeEventInsideACommunicationStep) {
  const Fmu fmu = OpenCoSimulation("step_response");
  const StepResponse exact{0.5, 0.33};  // inside the step from 0.30 to 0.35 s
  const std::vector<double> times = Grid(0.0, 2.0, 40);
  RunOptions options;
  options.parameters = {{"t_step_s", 0.33}};
  options.outputs = {"y"};
  options.output_times_s = times;
  auto result = Simulate(fmu, options);
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->outcome, RunOutcome::kOk) << result->reason;
  for (std::size_t i = 0; i < times.size(); ++i) {
    EXPECT_NEAR(result->values[0][i], exact.Y(times[i]), 1e-9) << "t = " << times[i];
  }
}

TEST(FmuCoSimulation, WallTimeLimitEndsTheRun) {
  const Fmu fmu = OpenCoSimulation("van_der_pol");
  RunOptions options;
  options.outputs = {"x0"};
  options.output_times_s = Grid(0.0, 40.0, 40);  // 40,000 steps of 1 ms
  // 1 s per reading of the clock: over the 100 s limit after 100 steps.
  const mbopt::testing::SteppingClock clock(1.0);
  const budget::AnalysisBudget budget =
      budget::AnalysisBudget(clock.AsClock(), nullptr).ForAnalysis(100.0, 0);
  options.budget = &budget;
  auto result = Simulate(fmu, options);
  ASSERT_TRUE(result.ok()) << result.status();
  EXPECT_EQ(result->outcome, RunOutcome::kTimeLimit);
  EXPECT_EQ(result->integrator_steps, 101);
}

TEST(FmuCoSimulation, OutputTimesOffTheCommunicationPointsAreRefused) {
  const Fmu fmu = OpenCoSimulation("damped_oscillator");
  RunOptions options;
  options.outputs = {"x_m"};
  options.output_times_s = {0.1, 0.125};
  auto result = Simulate(fmu, options);
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result.status().message(),
              HasSubstr("output time 1 (0.125 s) is not a whole number of communication steps (0.01 s)"));
}

TEST(FmuCoSimulation, ModelExchangeAndCoSimulationAgree) {
  const std::vector<double> times = Grid(0.0, 3.0, 30);
  RunOptions options;
  options.parameters = {{"mu", 0.5}};
  options.outputs = {"x0", "x1"};
  options.output_times_s = times;
  auto co_simulation = Simulate(OpenCoSimulation("van_der_pol"), options);
  // At rtol 1e-10 CVODES' global error reaches 1e-8 by t = 3 s; at 1e-12 it
  // stays below the 1e-9 compared here (as the Runge-Kutta substeps' does).
  options.relative_tolerance = 1e-12;
  options.absolute_tolerance = 1e-14;
  auto model_exchange = Simulate(*Fmu::Open(TestFmu("van_der_pol"), Interface::kModelExchange), options);
  ASSERT_TRUE(co_simulation.ok() && model_exchange.ok());
  ASSERT_EQ(co_simulation->outcome, RunOutcome::kOk) << co_simulation->reason;
  ASSERT_EQ(model_exchange->outcome, RunOutcome::kOk) << model_exchange->reason;
  for (int k = 0; k < 2; ++k) {
    for (std::size_t i = 0; i < times.size(); ++i) {
      EXPECT_NEAR(co_simulation->values[k][i], model_exchange->values[k][i], 1e-9) << k << " at t = " << times[i];
    }
  }
}

}  // namespace
}  // namespace mbopt::fmu
