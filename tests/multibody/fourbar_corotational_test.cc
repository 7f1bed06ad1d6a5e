// The report's elastic four-bar with co-rotational flexible links
// (examples/fourbar/fourbar_corotational.scene.textproto) against an
// independent co-rotational beam model of the same mechanism, which rates
// the report's optimum at 0.985 / 1.001 / 1.023 of the allowable stress
// (crank, coupler, rocker) and the 2.257 kg optimum of the linkage model at
// 1.018 / 1.047 / 0.992 (issue 12). The linkage model's elastodynamics
// (small elastic motion on the rigid one, second-order frame terms left
// out) rates the report's optimum at 0.968 / 0.963 / 1.029.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "worker/multibody/linkage_analysis.h"
#include "worker/multibody/scene_analysis.h"

namespace mbopt::multibody {
namespace {

constexpr double kAllowablePa = 2.758e7;

std::vector<double> StressRatios(const std::vector<double>& areas_m2) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile("examples/fourbar/fourbar_corotational.scene.textproto");
  EXPECT_TRUE(scene.ok()) << scene.status();
  if (!scene.ok()) return {};
  const spec::AnalysisReport report = AnalyzeMultibodyScene(*scene, areas_m2);
  EXPECT_TRUE(report.ok()) << report.failure.reason;
  EXPECT_EQ(report.formulation, spec::Formulation::kDynamic);
  std::vector<double> ratios;
  for (const spec::OutputValues& output : report.outputs) {
    double peak = 0.0;
    for (const std::vector<double>& node : output.series) {
      for (double value : node) peak = std::max(peak, std::abs(value));
    }
    ratios.push_back(peak / kAllowablePa);
  }
  return ratios;
}

// Agreement with the independent model: within 1 % of the allowable per
// link (measured: 0.5 %, 0.4 %, 0.1 % and 0.4 %, 0.7 %, 0.05 %).
constexpr double kAgreement = 0.01;

TEST(CorotationalFourBar, ReportOptimumAgreesWithTheIndependentCorotationalModel) {
  const std::vector<double> ratios = StressRatios({9.65e-4, 3.92e-4, 2.69e-4});
  ASSERT_EQ(ratios.size(), 3u);
  std::cout << "report's optimum: " << ratios[0] << " / " << ratios[1] << " / " << ratios[2] << "\n";
  EXPECT_NEAR(ratios[0], 0.985, kAgreement);
  EXPECT_NEAR(ratios[1], 1.001, kAgreement);
  EXPECT_NEAR(ratios[2], 1.023, kAgreement);
  // Farther from the linkage model's coupler (0.963) than the agreement.
  EXPECT_GT(ratios[1] - 0.963, 3 * kAgreement);
}

TEST(CorotationalFourBar, LinkageModelOptimumAgreesWithTheIndependentCorotationalModel) {
  const std::vector<double> ratios = StressRatios({9.137e-4, 3.571e-4, 2.801e-4});
  ASSERT_EQ(ratios.size(), 3u);
  std::cout << "2.257 kg optimum: " << ratios[0] << " / " << ratios[1] << " / " << ratios[2] << "\n";
  EXPECT_NEAR(ratios[0], 1.018, kAgreement);
  EXPECT_NEAR(ratios[1], 1.047, kAgreement);
  EXPECT_NEAR(ratios[2], 0.992, kAgreement);
}

// The co-rotational optimization's initial design at rtol 1e-9 fell into
// IDAS's step-growth trap (docs/benchmarks.md): order 1 from t = 0.33 s, an
// error-test failure after every accepted step, 34,691 steps. With the growth
// held to 1.5 once the cycle shows (forward_dynamics.cc) it takes some 5,800,
// and its stresses agree with the shipped tolerance's (rtol 1e-6, 0.026 % of
// the peak from a tight reference) to 0.1 % of each link's peak.
TEST(CorotationalFourBar, ATightToleranceDoesNotTrapTheStepControl) {
  absl::StatusOr<spec::Scene> scene =
      spec::io::LoadSceneFile("examples/fourbar/fourbar_elastic_corotational.scene.textproto");
  ASSERT_TRUE(scene.ok()) << scene.status();
  // As the study sets them: its variables times their scale.
  const std::vector<double> areas_m2 = {0.9137 * 1e-3, 0.3571 * 1e-3, 0.2801 * 1e-3};
  const spec::AnalysisReport shipped = AnalyzeLinkageScene(*scene, areas_m2);
  ASSERT_TRUE(shipped.ok()) << shipped.failure.reason;
  scene->integrator.relative_tolerance = 1e-9;
  scene->integrator.absolute_tolerance = 1e-12;
  const spec::AnalysisReport tight = AnalyzeLinkageScene(*scene, areas_m2);
  ASSERT_TRUE(tight.ok()) << tight.failure.reason;
  std::cout << "steps: " << shipped.counters.time_steps << " at rtol 1e-6, " << tight.counters.time_steps
            << " at rtol 1e-9\n";
  EXPECT_LT(tight.counters.time_steps, 12000);
  ASSERT_EQ(tight.outputs.size(), shipped.outputs.size());
  for (size_t k = 0; k < tight.outputs.size(); ++k) {
    double peak = 0.0, difference = 0.0;
    ASSERT_EQ(tight.outputs[k].series.size(), shipped.outputs[k].series.size());
    for (size_t j = 0; j < tight.outputs[k].series.size(); ++j) {
      const std::vector<double>& a = tight.outputs[k].series[j];
      const std::vector<double>& b = shipped.outputs[k].series[j];
      ASSERT_EQ(a.size(), b.size());
      for (size_t i = 0; i < a.size(); ++i) {
        peak = std::max(peak, std::abs(a[i]));
        difference = std::max(difference, std::abs(a[i] - b[i]));
      }
    }
    EXPECT_LT(difference, 1e-3 * peak) << tight.outputs[k].name;
  }
}

}  // namespace
}  // namespace mbopt::multibody
