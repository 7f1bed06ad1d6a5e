// Simulator sensitivities of flexible links' bending stresses (one series
// per node) against central differences of whole analyses: a cantilever
// propped by a spring at its tip in static equilibrium (the implicit
// function theorem), and a swinging flexible pendulum with structural
// damping (IDAS forward sensitivities). The parameters include the
// section's area and modulus, which change the stress at a fixed state
// (fibre distance, stiffness) as well as the state itself.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "worker/multibody/scene_analysis.h"

namespace mbopt::multibody {
namespace {

constexpr char kProppedCantilever[] = "tests/multibody/propped_cantilever.scene.textproto";

// The propped cantilever's rod, ten times softer, pinned at the wall and
// swinging down under gravity from horizontal, with 5 % structural damping
// (its rate follows the lowest bending frequency, hence the parameters).
constexpr char kFlexiblePendulum[] = R"pb(
name: "flexible_pendulum"
effects {
  gravity { acceleration_m_per_s2 { x { value: 0 } y { value: -9.81 } } }
  structural_damping { ratio_of_critical: 0.05 }
}
parameters { name: "A" value: 1e-4 unit: "m^2" }
parameters { name: "E" value: 2e10 unit: "Pa" }
parameters { name: "rho" value: 7800 unit: "kg/m^3" }
multibody {
  ground_markers { name: "pivot" }
  flexible_links {
    name: "rod"
    length_m { value: 1 }
    section { area_m2 { param: "A" } youngs_modulus_pa { param: "E" } density_kg_per_m3 { param: "rho" } }
    elements: 4
  }
  joints { name: "pin" kind: JOINT_REVOLUTE a: "ground.pivot" b: "rod.a" }
}
outputs { name: "tip_x" marker_position { marker: "rod.b" axis: AXIS_X } }
outputs { name: "stress" bending_stress { link: "rod" } }
time_grid { start_s: 0.02 end_s: 0.2 points: 10 }
integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-12 }
)pb";

absl::StatusOr<spec::Scene> LoadText(const std::string& text) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("mbopt_stress_sens_" + std::to_string(::getpid()) + ".textproto");
  std::ofstream(path) << text;
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile(path.string());
  std::filesystem::remove(path);
  return scene;
}

std::vector<double> Values(const spec::Scene& scene) {
  std::vector<double> p;
  for (const spec::Parameter& parameter : scene.parameters) p.push_back(parameter.value_si);
  return p;
}

// The largest difference, over every parameter, output, series and
// instant, between the simulator's derivative and a central difference of
// whole analyses (relative step `relative_step`), relative to the largest
// difference quotient of the same parameter and output (all its series).
double WorstRelativeDifference(const spec::Scene& scene, double relative_step) {
  const std::vector<double> p = Values(scene);
  std::vector<int> parameters;
  for (size_t i = 0; i < p.size(); ++i) parameters.push_back(static_cast<int>(i));
  const MultibodySensitivityResult result = AnalyzeMultibodySceneWithSensitivities(scene, p, parameters);
  EXPECT_TRUE(result.report.ok()) << result.report.failure.reason;
  EXPECT_EQ(result.unavailable, "");
  if (!result.report.ok() || result.output_derivatives.size() != p.size()) return INFINITY;
  double worst = 0.0;
  for (size_t i = 0; i < p.size(); ++i) {
    const double h = relative_step * std::abs(p[i]);
    std::vector<double> plus = p, minus = p;
    plus[i] += h;
    minus[i] -= h;
    const spec::AnalysisReport up = AnalyzeMultibodyScene(scene, plus), down = AnalyzeMultibodyScene(scene, minus);
    EXPECT_TRUE(up.ok() && down.ok());
    if (!up.ok() || !down.ok()) return INFINITY;
    EXPECT_EQ(result.output_derivatives[i].size(), up.outputs.size());
    for (size_t o = 0; o < up.outputs.size() && o < result.output_derivatives[i].size(); ++o) {
      const std::vector<std::vector<double>>& d = result.output_derivatives[i][o];
      EXPECT_EQ(d.size(), up.outputs[o].series.size()) << scene.outputs[o].name;
      if (d.size() != up.outputs[o].series.size()) return INFINITY;
      double scale = 0.0, diff = 0.0;
      for (size_t j = 0; j < d.size(); ++j) {
        EXPECT_EQ(d[j].size(), up.outputs[o].series[j].size());
        for (size_t t = 0; t < d[j].size() && t < up.outputs[o].series[j].size(); ++t) {
          const double fd = (up.outputs[o].series[j][t] - down.outputs[o].series[j][t]) / (2 * h);
          scale = std::max(scale, std::abs(fd));
          diff = std::max(diff, std::abs(d[j][t] - fd));
        }
      }
      // Every derivative here is far from zero: a missing term would show.
      EXPECT_GT(scale, 0.0) << scene.parameters[i].name << " -> " << scene.outputs[o].name;
      if (scale > 0.0) worst = std::max(worst, diff / scale);
      std::cout << scene.parameters[i].name << " -> " << scene.outputs[o].name << " (" << d.size()
                << " series): max |d| " << scale << ", difference " << diff << "\n";
    }
  }
  return worst;
}

TEST(StressSensitivity, StaticEquilibriumStressesAgreeWithCentralDifferences) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile(kProppedCantilever);
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(MultibodySensitivityUnavailable(*scene), "");
  const spec::AnalysisReport report = AnalyzeMultibodyScene(*scene, Values(*scene));
  ASSERT_TRUE(report.ok()) << report.failure.reason;
  EXPECT_EQ(report.formulation, spec::Formulation::kStatic);
  // Linear theory: the spring takes k / (k + 3 EI / L^3) of the load, the
  // root carries the rest times L; M r / I with r / I = 7.09e6 / m^3.
  const double area = 1e-4, inertia = area * area / (4 * M_PI), tip_stiffness = 3 * 2e11 * inertia;
  const double root = -10.0 * (tip_stiffness / (500.0 + tip_stiffness)) * std::sqrt(area / M_PI) / inertia;
  EXPECT_NEAR(report.outputs[1].series[0][0] / root, 1.0, 1e-3);
  // Measured: 4.0e-6 (the tip displacement's derivatives too, so not the
  // stresses' own: at a tenth of the load the A, k and P columns agree to
  // 7e-8, the L column stays at 2.5e-6). Steps 1e-5 and 1e-4 give the same
  // figures: it is not the differences' noise.
  const double worst = WorstRelativeDifference(*scene, 1e-4);
  std::cout << "worst relative difference " << worst << "\n";
  EXPECT_LT(worst, 1e-5);
}

TEST(StressSensitivity, ForwardDynamicsStressesAgreeWithCentralDifferences) {
  absl::StatusOr<spec::Scene> scene = LoadText(kFlexiblePendulum);
  ASSERT_TRUE(scene.ok()) << scene.status();
  // Differences at 1e-3 (at 1e-4 their noise, rtol / step, shows in the
  // small rho -> tip_x column); measured 9.8e-6, the bound that of the
  // other forward-dynamics sensitivity tests.
  const double worst = WorstRelativeDifference(*scene, 1e-3);
  std::cout << "worst relative difference " << worst << "\n";
  EXPECT_LT(worst, 1e-4);
}

}  // namespace
}  // namespace mbopt::multibody
