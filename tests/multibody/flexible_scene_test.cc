// Flexible links written in a scene file: a clamped cantilever under a tip
// load (static equilibrium: tip deflection and root stress against closed
// forms), a flexible pendulum (forward dynamics: energy from the outputs),
// and the loader's errors.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "worker/multibody/scene_analysis.h"

namespace mbopt::multibody {
namespace {

using ::testing::HasSubstr;

// Steel rod, 1 m, area 1e-4 m^2: EI = E A^2 / (4 pi) = 159.15 N m^2.
constexpr char kCantilever[] = R"pb(
name: "cantilever"
multibody {
  %ANALYSIS%
  ground_markers { name: "wall" }
  flexible_links {
    name: "rod"
    length_m { value: 1 }
    section { area_m2 { value: 1e-4 } youngs_modulus_pa { value: 2e11 } density_kg_per_m3 { value: 7800 } }
    elements: 8
  }
  joints { name: "clamp" kind: JOINT_FIXED a: "ground.wall" b: "rod.a" }
  %LOADS%
}
%OUTPUTS%
time_grid { start_s: %START% end_s: %END% points: %POINTS% }
integrator { relative_tolerance: 1e-8 absolute_tolerance: 1e-10 }
)pb";

std::string Substitute(std::string text, const std::string& key, const std::string& value) {
  const size_t at = text.find(key);
  if (at != std::string::npos) text.replace(at, key.size(), value);
  return text;
}

absl::StatusOr<spec::Scene> LoadText(const std::string& text) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("mbopt_flexible_" + std::to_string(::getpid()) + ".textproto");
  std::ofstream(path) << text;
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile(path.string());
  std::filesystem::remove(path);
  return scene;
}

TEST(FlexibleLinkScene, StaticCantileverMatchesBeamTheory) {
  std::string text = kCantilever;
  text = Substitute(text, "%ANALYSIS%", "analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM");
  text = Substitute(text, "%LOADS%", R"(point_forces { at: "rod.b" force_n { x { value: 0 } y { value: -1 } } })");
  text = Substitute(text, "%OUTPUTS%", R"(outputs { name: "tip_y" marker_position { marker: "rod.b" axis: AXIS_Y } }
outputs { name: "stress" bending_stress { link: "rod" } })");
  text = Substitute(Substitute(Substitute(text, "%START%", "0"), "%END%", "0"), "%POINTS%", "1");
  absl::StatusOr<spec::Scene> scene = LoadText(text);
  ASSERT_TRUE(scene.ok()) << scene.status();
  const spec::AnalysisReport report = AnalyzeMultibodyScene(*scene, {});
  ASSERT_TRUE(report.ok()) << report.failure.reason;
  EXPECT_EQ(report.formulation, spec::Formulation::kStatic);
  const double area = 1e-4, inertia = area * area / (4 * std::numbers::pi), ei = 2e11 * inertia;
  const double radius = std::sqrt(area / std::numbers::pi);
  // 1 N at the tip: deflection P L^3 / 3 EI (2.1 mm: linear to 1e-5).
  EXPECT_NEAR(report.outputs[0].series[0][0] / (-1.0 / (3 * ei)), 1.0, 1e-5);
  // Stress at the nodes, M(x) r / I with M = -P (L - x) (hogging): the root
  // carries P L, the tip nothing. (The tip moves in by about 3 delta^2 / 5 L,
  // shortening the lever by 2.6e-6 L: the tolerance is 1e-5 of the root's.)
  ASSERT_EQ(report.outputs[1].series.size(), 9u);
  EXPECT_EQ(report.outputs[1].series_labels[0], "node 0");
  for (int node = 0; node <= 8; ++node) {
    const double expected = -1.0 * (1.0 - node / 8.0) * radius / inertia;
    EXPECT_NEAR(report.outputs[1].series[static_cast<size_t>(node)][0], expected, 1e-5 * radius / inertia)
        << "node " << node;
  }
}

TEST(FlexibleLinkScene, FlexiblePendulumOutputsConserveEnergy) {
  std::string text = kCantilever;
  text = Substitute(text, "%ANALYSIS%", "");
  text = Substitute(text, "kind: JOINT_FIXED", "kind: JOINT_REVOLUTE");
  text = Substitute(text, "%LOADS%", "");
  text = Substitute(text, "name: \"cantilever\"",
                    "name: \"pendulum\"\neffects { gravity { acceleration_m_per_s2 { x { value: 0 } y { value: -9.81 } } } }");
  text = Substitute(text, "%OUTPUTS%", R"(outputs { name: "kinetic" kinetic_energy {} }
outputs { name: "potential" potential_energy {} }
outputs { name: "stress" bending_stress { link: "rod" } })");
  text = Substitute(Substitute(Substitute(text, "%START%", "0"), "%END%", "0.5"), "%POINTS%", "51");
  absl::StatusOr<spec::Scene> scene = LoadText(text);
  ASSERT_TRUE(scene.ok()) << scene.status();
  const spec::AnalysisReport report = AnalyzeMultibodyScene(*scene, {});
  ASSERT_TRUE(report.ok()) << report.failure.reason;
  EXPECT_EQ(report.formulation, spec::Formulation::kDynamic);
  const double start = report.outputs[0].series[0][0] + report.outputs[1].series[0][0];
  double drift = 0.0, peak_stress = 0.0;
  for (size_t i = 0; i < report.times_s.size(); ++i) {
    drift = std::max(drift, std::abs(report.outputs[0].series[0][i] + report.outputs[1].series[0][i] - start));
    for (const std::vector<double>& node : report.outputs[2].series) peak_stress = std::max(peak_stress, std::abs(node[i]));
  }
  // 0.78 kg falling 0.5 m: a few J change hands.
  EXPECT_GT(report.outputs[0].series[0].back(), 1.0);
  EXPECT_LT(drift, 1e-5);
  EXPECT_GT(peak_stress, 1e5);  // the swinging rod bends
}

TEST(FlexibleLinkScene, UnknownEndAndElementBoundsAreNamed) {
  std::string text = kCantilever;
  text = Substitute(text, "%ANALYSIS%", "");
  text = Substitute(text, "b: \"rod.a\"", "b: \"rod.middle\"");
  text = Substitute(text, "elements: 8", "elements: 5000");
  text = Substitute(text, "%LOADS%", "");
  text = Substitute(text, "%OUTPUTS%", "");
  text = Substitute(Substitute(Substitute(text, "%START%", "0"), "%END%", "0"), "%POINTS%", "1");
  absl::StatusOr<spec::Scene> scene = LoadText(text);
  ASSERT_FALSE(scene.ok());
  const std::string message(scene.status().message());
  EXPECT_THAT(message, HasSubstr("flexible link \"rod\" has ends \"a\" and \"b\", not \"middle\""));
  EXPECT_THAT(message, HasSubstr("flexible_links[0].elements: expected 1 to 200 elements"));
}

}  // namespace
}  // namespace mbopt::multibody
