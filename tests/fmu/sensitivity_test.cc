// Forward sensitivities of FMU outputs through the FMU's directional
// derivatives (FMI 2.0 and 3.0), against the closed form and against
// differences of plain runs.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "tests/fmu/closed_forms.h"
#include "worker/fmu/fmu.h"
#include "worker/fmu/sensitivities.h"
#include "worker/fmu/simulation.h"

namespace mbopt::fmu {
namespace {

using ::testing::HasSubstr;
using testing::DampedOscillator;
using testing::Grid;
using testing::TestFmu;

Fmu Open(const std::string& name, Interface interface = Interface::kModelExchange) {
  auto fmu = Fmu::Open(TestFmu(name), interface);
  EXPECT_TRUE(fmu.ok()) << fmu.status();
  return *std::move(fmu);
}

constexpr double kMassKg = 1.5;
constexpr double kDamping = 0.5;
constexpr double kStiffness = 6.0;
constexpr double kX0 = 0.2;

RunOptions Oscillator(double stiffness, double damping) {
  RunOptions options;
  options.parameters = {{"mass_kg", kMassKg}, {"stiffness_n_per_m", stiffness}, {"damping_n_s_per_m", damping},
                        {"x0_m", kX0}};
  options.outputs = {"x_m", "spring_force_n"};
  options.output_times_s = Grid(0.0, 6.0, 120);
  options.relative_tolerance = 1e-10;
  options.absolute_tolerance = 1e-12;
  return options;
}

// d X / d k and d X / d c of the closed form, by central differences of the
// formula itself (no integration): rounding and truncation ~1e-11 here.
double ClosedFormDerivative(double t, int parameter) {
  const double h = 1e-6;
  auto x = [&](double dk, double dc) { return DampedOscillator{kMassKg, kDamping + dc, kStiffness + dk, kX0}.X(t); };
  return parameter == 0 ? (x(h, 0) - x(-h, 0)) / (2 * h) : (x(0, h) - x(0, -h)) / (2 * h);
}

class FmuSensitivity : public ::testing::TestWithParam<std::string> {};

TEST_P(FmuSensitivity, OscillatorDerivativesFollowTheClosedForm) {
  const Fmu fmu = Open(GetParam());
  auto result = SimulateWithSensitivities(fmu, Oscillator(kStiffness, kDamping), {1, 2});
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->run.outcome, RunOutcome::kOk) << result->run.reason;
  ASSERT_EQ(result->unavailable, "");
  ASSERT_EQ(result->output_derivatives.size(), 2u);
  const std::vector<double> times = Grid(0.0, 6.0, 120);
  double largest = 0.0;
  for (std::size_t i = 0; i < times.size(); ++i) {
    const double t = times[i];
    const double x = DampedOscillator{kMassKg, kDamping, kStiffness, kX0}.X(t);
    for (int k = 0; k < 2; ++k) {
      const double dx = ClosedFormDerivative(t, k);
      largest = std::max(largest, std::abs(dx));
      EXPECT_NEAR(result->output_derivatives[k][0][i], dx, 1e-7) << "d x / d p" << k << " at t = " << t;
      // The spring force -k x is no state: its derivative comes from the FMU.
      const double dforce = -kStiffness * dx - (k == 0 ? x : 0.0);
      EXPECT_NEAR(result->output_derivatives[k][1][i], dforce, kStiffness * 1e-7) << "at t = " << t;
    }
  }
  EXPECT_GT(largest, 0.01) << "the derivatives compared are not all ~0";
}

TEST_P(FmuSensitivity, AgreesWithDifferencesOfPlainRuns) {
  const Fmu fmu = Open(GetParam());
  auto result = SimulateWithSensitivities(fmu, Oscillator(kStiffness, kDamping), {1, 2});
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->unavailable, "");
  const double h_k = 1e-5 * kStiffness;
  const double h_c = 1e-5 * kDamping;
  auto up_k = Simulate(fmu, Oscillator(kStiffness + h_k, kDamping));
  auto down_k = Simulate(fmu, Oscillator(kStiffness - h_k, kDamping));
  auto up_c = Simulate(fmu, Oscillator(kStiffness, kDamping + h_c));
  auto down_c = Simulate(fmu, Oscillator(kStiffness, kDamping - h_c));
  ASSERT_TRUE(up_k.ok() && down_k.ok() && up_c.ok() && down_c.ok());
  for (std::size_t i = 0; i < up_k->values[0].size(); ++i) {
    const double dk = (up_k->values[0][i] - down_k->values[0][i]) / (2 * h_k);
    const double dc = (up_c->values[0][i] - down_c->values[0][i]) / (2 * h_c);
    EXPECT_NEAR(result->output_derivatives[0][0][i], dk, 1e-5) << i;
    EXPECT_NEAR(result->output_derivatives[1][0][i], dc, 1e-5) << i;
  }
  // The values are those of the plain run (to the integrator's tolerance:
  // the sensitivities take part in its step-size choice).
  auto plain = Simulate(fmu, Oscillator(kStiffness, kDamping));
  ASSERT_TRUE(plain.ok());
  for (std::size_t i = 0; i < plain->values[0].size(); ++i) {
    EXPECT_NEAR(result->run.values[0][i], plain->values[0][i], 1e-8) << i;
  }
}

TEST_P(FmuSensitivity, TheInitialPositionsDerivativeStartsAtOne) {
  const Fmu fmu = Open(GetParam());
  auto result = SimulateWithSensitivities(fmu, Oscillator(kStiffness, kDamping), {3});
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->unavailable, "");
  // x is linear in x0: d x / d x0 = x / x0 all along.
  EXPECT_EQ(result->output_derivatives[0][0][0], 1.0);
  for (std::size_t i = 0; i < result->run.values[0].size(); ++i) {
    EXPECT_NEAR(result->output_derivatives[0][0][i], result->run.values[0][i] / kX0, 1e-7) << i;
  }
}

INSTANTIATE_TEST_SUITE_P(Fmi2AndFmi3, FmuSensitivity, ::testing::Values("damped_oscillator", "damped_oscillator_fmi3"));

TEST(FmuSensitivityUnavailable, SaysWhatIsMissing) {
  EXPECT_THAT(SensitivitiesUnavailable(Open("damped_oscillator"), {"mass_kg"}),
              HasSubstr("FMU parameter \"mass_kg\" is not tunable; directional derivatives with respect to a "
                        "parameter need variability=\"tunable\""));
  EXPECT_THAT(SensitivitiesUnavailable(Open("damped_oscillator", Interface::kCoSimulation), {"stiffness_n_per_m"}),
              HasSubstr("a Co-Simulation FMU integrates itself"));
  EXPECT_THAT(SensitivitiesUnavailable(Open("bouncing_ball"), {"e"}),
              HasSubstr("the FMU does not declare providesDirectionalDerivative=\"true\" on <ModelExchange>"));
  EXPECT_THAT(SensitivitiesUnavailable(Open("bouncing_ball_fmi3"), {"e"}),
              HasSubstr("providesDirectionalDerivatives=\"true\""));
  EXPECT_EQ(SensitivitiesUnavailable(Open("damped_oscillator_fmi3"), {"stiffness_n_per_m", "damping_n_s_per_m"}), "");
}

// The lag's input steps at a time event: the run goes on with its values,
// the sensitivities are given up with the event's time as the reason.
TEST(FmuSensitivityUnavailable, ATimeEventEndsTheSensitivitiesNotTheRun) {
  RunOptions options;
  options.parameters = {{"tau_s", 0.25}, {"t_step_s", 0.37}};
  options.outputs = {"y"};
  options.output_times_s = Grid(0.0, 2.0, 100);
  auto result = SimulateWithSensitivities(Open("step_response"), options, {0});
  ASSERT_TRUE(result.ok()) << result.status();
  ASSERT_EQ(result->run.outcome, RunOutcome::kOk) << result->run.reason;
  EXPECT_EQ(result->unavailable, "an event at t = 0.37 s: sensitivities across events are not computed");
  EXPECT_TRUE(result->output_derivatives.empty());
  const testing::StepResponse exact{0.25, 0.37};
  EXPECT_NEAR(result->run.values[0][100], exact.Y(2.0), 1e-6);
}

TEST(FmuSensitivityUnavailable, SimulateWithSensitivitiesRefusesWhatIsUnavailable) {
  auto result = SimulateWithSensitivities(Open("damped_oscillator"), Oscillator(kStiffness, kDamping), {0});
  ASSERT_FALSE(result.ok());
  EXPECT_THAT(result.status().message(), HasSubstr("\"mass_kg\" is not tunable"));
}

}  // namespace
}  // namespace mbopt::fmu
