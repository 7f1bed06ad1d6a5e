// Simulator sensitivities of multibody analyses: IDAS forward sensitivities
// against SUNDIALS' published dG/dp of its slider-crank, and both paths
// (forward dynamics, driven kinematics with inverse dynamics) against
// central differences of whole analyses on the examples, including a link
// length that enters through expressions.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/multibody/mechanisms.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/scene_analysis.h"

namespace mbopt::multibody {
namespace {

// G = integral of the kinetic energy over 10 s (Simpson on 10,000
// intervals) and dG/dk, dG/dc from IDAS forward sensitivities, at the
// example's own tolerances.
TEST(MultibodySensitivity, SundialsSliderCrankForwardSensitivitiesMatchThePublishedAnswer) {
  constexpr double k = 1.0, c = 1.0, step = 1e-5;
  const Model nominal = testing::SundialsSliderCrank(k, c);
  const Model k_plus = testing::SundialsSliderCrank(k + step, c), k_minus = testing::SundialsSliderCrank(k - step, c);
  const Model c_plus = testing::SundialsSliderCrank(k, c + step), c_minus = testing::SundialsSliderCrank(k, c - step);
  const Mechanism m(nominal), mkp(k_plus), mkm(k_minus), mcp(c_plus), mcm(c_minus);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  ForwardSensitivityInput input;
  input.parameters = {ParameterPerturbation{&mkp, &mkm, step, 1.0}, ParameterPerturbation{&mcp, &mcm, step, 1.0}};
  // The start does not depend on k or c (at rest, same assembly).
  input.q0.assign(2, Eigen::VectorXd::Zero(m.num_coordinates()));
  input.v0.assign(2, Eigen::VectorXd::Zero(m.num_coordinates()));
  ForwardDynamicsOptions options;
  options.relative_tolerance = 1e-6;
  options.absolute_tolerance = 1e-7;
  std::vector<double> times;
  for (int i = 0; i <= 10000; ++i) times.push_back(10.0 * i / 10000);
  std::vector<double> energy, d_energy_dk, d_energy_dc;
  Eigen::MatrixXd mass;
  ForwardDynamicsCounters counters;
  const spec::AnalysisFailure f = IntegrateForward(
      m, 0.0, assembled.q, assembled.v, times, options,
      [&](const MotionSample& s) {
        m.MassMatrix(s.q, &mass);
        energy.push_back(0.5 * s.v.dot(mass * s.v));
        EXPECT_EQ(s.sensitivities.size(), 2u);
        d_energy_dk.push_back(s.v.dot(mass * s.sensitivities[0].v));
        d_energy_dc.push_back(s.v.dot(mass * s.sensitivities[1].v));
        return spec::AnalysisFailure::Ok();
      },
      &counters, &input);
  ASSERT_TRUE(f.ok()) << f.reason;
  auto simpson = [&](const std::vector<double>& y) {
    const double h = times[1] - times[0];
    double sum = y.front() + y.back();
    for (size_t i = 1; i + 1 < y.size(); ++i) sum += (i % 2 == 1 ? 4.0 : 2.0) * y[i];
    return sum * h / 3.0;
  };
  // The example prints 5 digits: G = 3.33661580, dG/dp = (0.33346, -0.36375).
  EXPECT_NEAR(simpson(energy), 3.3366158, 3.3366158 * 2e-5);
  EXPECT_NEAR(simpson(d_energy_dk), 0.33346, 5e-5);
  EXPECT_NEAR(simpson(d_energy_dc), -0.36375, 5e-5);
  std::cout << std::setprecision(8) << "G = " << simpson(energy) << ", dG/dk = " << simpson(d_energy_dk)
            << ", dG/dc = " << simpson(d_energy_dc) << " (" << counters.steps << " steps)\n";
}

// The largest difference between the simulator's derivatives and central
// differences of whole analyses (relative step `relative_step`), relative to
// the largest derivative of the same output.
double WorstRelativeDifference(const spec::Scene& scene, const std::vector<double>& p, double relative_step) {
  std::vector<int> parameters;
  for (size_t i = 0; i < p.size(); ++i) parameters.push_back(static_cast<int>(i));
  const MultibodySensitivityResult result = AnalyzeMultibodySceneWithSensitivities(scene, p, parameters);
  EXPECT_TRUE(result.report.ok()) << result.report.failure.reason;
  EXPECT_EQ(result.unavailable, "");
  if (!result.report.ok() || result.output_derivatives.size() != p.size()) return INFINITY;
  // The values are those of the plain analysis, to the integration
  // tolerance (the sensitivities in the error test change the steps).
  const spec::AnalysisReport plain = AnalyzeMultibodyScene(scene, p);
  for (size_t o = 0; o < plain.outputs.size(); ++o) {
    for (size_t t = 0; t < plain.outputs[o].series[0].size(); ++t) {
      EXPECT_NEAR(result.report.outputs[o].series[0][t], plain.outputs[o].series[0][t],
                  100 * scene.integrator.relative_tolerance * (1.0 + std::abs(plain.outputs[o].series[0][t])));
    }
  }
  double worst = 0.0;
  for (size_t i = 0; i < p.size(); ++i) {
    const double h = relative_step * std::abs(p[i]);
    std::vector<double> plus = p, minus = p;
    plus[i] += h;
    minus[i] -= h;
    const spec::AnalysisReport up = AnalyzeMultibodyScene(scene, plus), down = AnalyzeMultibodyScene(scene, minus);
    EXPECT_TRUE(up.ok() && down.ok());
    for (size_t o = 0; o < up.outputs.size(); ++o) {
      const std::vector<double>& d = result.output_derivatives[i][o][0];
      EXPECT_EQ(d.size(), up.outputs[o].series[0].size());
      double scale = 0.0, diff = 0.0;
      for (size_t t = 0; t < d.size(); ++t) {
        const double fd = (up.outputs[o].series[0][t] - down.outputs[o].series[0][t]) / (2 * h);
        scale = std::max(scale, std::abs(fd));
        diff = std::max(diff, std::abs(d[t] - fd));
      }
      if (scale > 0.0) worst = std::max(worst, diff / scale);
      std::cout << scene.parameters[i].name << " -> " << scene.outputs[o].name << ": max |d| " << scale
                << ", difference " << diff << "\n";
    }
  }
  return worst;
}

std::vector<double> Values(const spec::Scene& scene) {
  std::vector<double> p;
  for (const spec::Parameter& parameter : scene.parameters) p.push_back(parameter.value_si);
  return p;
}

// Forward dynamics with IDAS sensitivities: the isolator (stiffness and
// damping of its spring), integrated at rtol 1e-8.
TEST(MultibodySensitivity, FreeMotionDerivativesAgreeWithCentralDifferences) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile("examples/isolator/isolator.scene.textproto");
  ASSERT_TRUE(scene.ok()) << scene.status();
  // Tighter than the example (1e-8) so that the central differences (noise
  // about rtol / step = 1e-6) can judge the sensitivities.
  scene->integrator.relative_tolerance = 1e-10;
  scene->integrator.absolute_tolerance = 1e-11;
  EXPECT_LT(WorstRelativeDifference(*scene, Values(*scene), 1e-4), 1e-4);
}

// A driven mechanism: the press, whose parameters are the crank radius and
// the rod length (markers, start position and inertia through expressions),
// with the drive torque from inverse dynamics.
TEST(MultibodySensitivity, DrivenMechanismDerivativesAgreeWithCentralDifferences) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile("examples/press/press.scene.textproto");
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_LT(WorstRelativeDifference(*scene, Values(*scene), 1e-5), 1e-6);
}

}  // namespace
}  // namespace mbopt::multibody
