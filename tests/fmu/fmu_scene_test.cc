// The `fmu` scene kind: read from files (the FMU path taken from the scene
// file's folder), checked, and analysed through the engine.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <variant>

#include "spec/io/study_io.h"
#include "tests/fmu/closed_forms.h"
#include "tests/testing/temp_dir.h"
#include "worker/engine/analysis.h"
#include "worker/fmu/scene_analysis.h"

namespace mbopt::fmu {
namespace {

using ::testing::HasSubstr;
using testing::DampedOscillator;
using testing::TestFmu;

class FmuScene : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = dir_.path();
    std::filesystem::create_directory(folder_ / "models");
    std::filesystem::copy_file(TestFmu("damped_oscillator"), folder_ / "models" / "oscillator.fmu");
  }

  std::string Write(const std::string& name, const std::string& text) {
    const std::filesystem::path path = folder_ / name;
    std::ofstream(path) << text;
    return path.string();
  }

  static std::string Scene(const std::string& fmu_body, const std::string& outputs) {
    return R"pb(
name: "s"
parameters { name: "stiffness" value: 9 unit: "N/m" }
fmu {
)pb" + fmu_body + R"pb(
}
)pb" + outputs + R"pb(
time_grid { start_s: 0 end_s: 3 points: 31 }
integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-12 }
)pb";
  }

  static constexpr char kOscillator[] = R"pb(
  path: "models/oscillator.fmu"
  parameters { variable: "stiffness_n_per_m" value { param: "stiffness" } }
  parameters { variable: "damping_n_s_per_m" value { value: 0.5 } })pb";
  static constexpr char kPositionAndForce[] = R"pb(
outputs { name: "position" fmu_variable { variable: "x_m" } }
outputs { name: "force" fmu_variable { variable: "spring_force_n" } })pb";

  ::mbopt::testing::TempDir dir_;
  std::filesystem::path folder_;
};

TEST_F(FmuScene, ARelativeFmuPathIsTakenFromTheSceneFilesFolder) {
  auto scene = spec::io::LoadSceneFile(Write("s.scene.textproto", Scene(kOscillator, kPositionAndForce)));
  ASSERT_TRUE(scene.ok()) << scene.status();
  const auto* model = std::get_if<spec::FmuModel>(&scene->model);
  ASSERT_NE(model, nullptr);
  EXPECT_EQ(model->path, (folder_ / "models" / "oscillator.fmu").string());
  EXPECT_FALSE(model->co_simulation);
  ASSERT_EQ(model->parameters.size(), 2u);
  EXPECT_EQ(model->parameters[0].variable, "stiffness_n_per_m");
  EXPECT_EQ(model->parameters[0].value.param, 0);
}

TEST_F(FmuScene, AMissingFmuFileIsNamedWhenTheSceneIsRead) {
  const std::string body = R"pb(path: "models/nothing.fmu")pb";
  auto scene = spec::io::LoadSceneFile(Write("s.scene.textproto", Scene(body, kPositionAndForce)));
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(scene.status().message(), HasSubstr("s.scene.textproto: fmu.path: no FMU file"));
  EXPECT_THAT(scene.status().message(), HasSubstr("models/nothing.fmu"));
}

TEST_F(FmuScene, OutputsOfOtherModelKindsAndFmuOutputsElsewhereAreRefused) {
  auto scene = spec::io::LoadSceneFile(
      Write("s.scene.textproto", Scene(kOscillator, R"pb(outputs { name: "m" mass {} })pb")));
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(scene.status().message(), HasSubstr("output \"m\" needs a linkage model; this scene's model is fmu"));
}

TEST_F(FmuScene, ACommunicationStepNeedsCoSimulation) {
  const std::string body = std::string(kOscillator) + "\n  communication_step_s: 0.01";
  auto scene = spec::io::LoadSceneFile(Write("s.scene.textproto", Scene(body, kPositionAndForce)));
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(scene.status().message(), HasSubstr("applies to `interface: FMU_CO_SIMULATION` only"));
}

TEST_F(FmuScene, AnalysisReportsTheFmuVariablesOnTheGridAtTheDesignsValues) {
  auto scene = spec::io::LoadSceneFile(Write("s.scene.textproto", Scene(kOscillator, kPositionAndForce)));
  ASSERT_TRUE(scene.ok()) << scene.status();
  const spec::AnalysisReport report = engine::Analyze(*scene, {16.0});  // stiffness 16 N/m, not the scene's 9
  ASSERT_TRUE(report.ok()) << report.failure.reason;
  const DampedOscillator exact{1.0, 0.5, 16.0, 0.1};
  ASSERT_EQ(report.outputs.size(), 2u);
  EXPECT_EQ(report.outputs[0].name, "position");
  ASSERT_EQ(report.times_s.size(), 31u);
  for (std::size_t i = 0; i < report.times_s.size(); ++i) {
    EXPECT_NEAR(report.outputs[0].series[0][i], exact.X(report.times_s[i]), 1e-8);
    EXPECT_NEAR(report.outputs[1].series[0][i], -16.0 * exact.X(report.times_s[i]), 16e-8);
  }
  EXPECT_GT(report.counters.time_steps, 0);
}

// An FMI 3.0 FMU is a scene like any other: the same scene file over the
// oscillator's FMI 3.0 build reports what its FMI 2.0 build does, bit for
// bit, with simulator sensitivities too.
TEST_F(FmuScene, AnFmi3FmuRunsThroughTheSameSceneAsItsFmi2Build) {
  std::filesystem::copy_file(TestFmu("damped_oscillator_fmi3"), folder_ / "models" / "oscillator3.fmu");
  std::string body = kOscillator;
  body.replace(body.find("oscillator.fmu"), 14, "oscillator3.fmu");
  auto fmi3 = spec::io::LoadSceneFile(Write("s3.scene.textproto", Scene(body, kPositionAndForce)));
  auto fmi2 = spec::io::LoadSceneFile(Write("s.scene.textproto", Scene(kOscillator, kPositionAndForce)));
  ASSERT_TRUE(fmi3.ok() && fmi2.ok());
  const spec::AnalysisReport report3 = engine::Analyze(*fmi3, {16.0});
  const spec::AnalysisReport report2 = engine::Analyze(*fmi2, {16.0});
  ASSERT_TRUE(report3.ok()) << report3.failure.reason;
  ASSERT_TRUE(report2.ok()) << report2.failure.reason;
  const DampedOscillator exact{1.0, 0.5, 16.0, 0.1};
  for (std::size_t i = 0; i < report3.times_s.size(); ++i) {
    EXPECT_NEAR(report3.outputs[0].series[0][i], exact.X(report3.times_s[i]), 1e-8);
  }
  EXPECT_EQ(report3.outputs[0].series, report2.outputs[0].series);
  EXPECT_EQ(report3.outputs[1].series, report2.outputs[1].series);
  const FmuSensitivityAnalysis with3 = AnalyzeFmuSceneWithSensitivities(*fmi3, {16.0}, {0});
  const FmuSensitivityAnalysis with2 = AnalyzeFmuSceneWithSensitivities(*fmi2, {16.0}, {0});
  ASSERT_EQ(with3.unavailable, "");
  ASSERT_EQ(with3.output_derivatives.size(), 1u);
  EXPECT_EQ(with3.output_derivatives, with2.output_derivatives);
}

TEST_F(FmuScene, CoSimulationSceneSteppedAtItsCommunicationStep) {
  const std::string body = std::string(kOscillator) + "\n  interface: FMU_CO_SIMULATION communication_step_s: 0.005";
  auto scene = spec::io::LoadSceneFile(Write("s.scene.textproto", Scene(body, kPositionAndForce)));
  ASSERT_TRUE(scene.ok()) << scene.status();
  const spec::AnalysisReport report = engine::Analyze(*scene, {9.0});
  ASSERT_TRUE(report.ok()) << report.failure.reason;
  EXPECT_EQ(report.counters.time_steps, 600);  // 3 s in 5 ms steps
  const DampedOscillator exact{1.0, 0.5, 9.0, 0.1};
  EXPECT_NEAR(report.outputs[0].series[0].back(), exact.X(3.0), 1e-9);
}

TEST_F(FmuScene, AnFmuVariableThatDoesNotExistFailsTheAnalysisNamingThoseThatDo) {
  auto scene = spec::io::LoadSceneFile(Write(
      "s.scene.textproto", Scene(kOscillator, R"pb(outputs { name: "p" fmu_variable { variable: "x" } })pb")));
  ASSERT_TRUE(scene.ok()) << scene.status();  // the FMU's names are checked when it is opened
  const spec::AnalysisReport report = engine::Analyze(*scene, {9.0});
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_THAT(report.failure.reason, HasSubstr("named \"x\" to output; its Real variables are: x_m, v_m_per_s"));
}

TEST_F(FmuScene, TheFmusOwnErrorFailsTheAnalysisAsAnInvalidModel) {
  const std::string body = std::string(kOscillator) + "\n  parameters { variable: \"mass_kg\" value { value: 0 } }";
  auto scene = spec::io::LoadSceneFile(Write("s.scene.textproto", Scene(body, kPositionAndForce)));
  ASSERT_TRUE(scene.ok()) << scene.status();
  const spec::AnalysisReport report = engine::Analyze(*scene, {9.0});
  ASSERT_FALSE(report.ok());
  EXPECT_EQ(report.failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_THAT(report.failure.reason, HasSubstr("mass_kg must be > 0, got 0"));
}

// Simulator sensitivities of an FMU scene: the chain rule through the
// bindings (a scene parameter setting two FMU parameters through
// expressions), against differences of plain analyses.
TEST_F(FmuScene, SensitivitiesFollowTheBindingsExpressions) {
  const std::string body = R"pb(
  path: "models/oscillator.fmu"
  parameters { variable: "stiffness_n_per_m" value { expr: "2 * stiffness" } }
  parameters { variable: "damping_n_s_per_m" value { expr: "0.1 * stiffness" } })pb";
  auto scene = spec::io::LoadSceneFile(Write("s.scene.textproto", Scene(body, kPositionAndForce)));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(FmuSensitivitiesUnavailable(*scene, {0}), "");
  const double k = 9.0;
  FmuSensitivityAnalysis with = AnalyzeFmuSceneWithSensitivities(*scene, {k}, {0});
  ASSERT_TRUE(with.report.ok()) << with.report.failure.reason;
  ASSERT_EQ(with.unavailable, "");
  ASSERT_EQ(with.output_derivatives.size(), 1u);
  const double h = 1e-5 * k;
  const spec::AnalysisReport up = engine::Analyze(*scene, {k + h});
  const spec::AnalysisReport down = engine::Analyze(*scene, {k - h});
  ASSERT_TRUE(up.ok() && down.ok());
  double largest = 0.0;
  for (std::size_t o = 0; o < 2; ++o) {
    for (std::size_t i = 0; i < with.report.times_s.size(); ++i) {
      const double difference = (up.outputs[o].series[0][i] - down.outputs[o].series[0][i]) / (2 * h);
      largest = std::max(largest, std::abs(difference));
      EXPECT_NEAR(with.output_derivatives[0][o][i], difference, 1e-5) << "output " << o << " at " << i;
    }
  }
  EXPECT_GT(largest, 1e-2);
}

TEST_F(FmuScene, SensitivitiesUnavailableSayWhy) {
  const std::string fixed_mass = std::string(kOscillator) + R"pb(
  parameters { variable: "mass_kg" value { param: "stiffness" } })pb";
  auto scene = spec::io::LoadSceneFile(Write("s.scene.textproto", Scene(fixed_mass, kPositionAndForce)));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_THAT(FmuSensitivitiesUnavailable(*scene, {0}), HasSubstr("FMU parameter \"mass_kg\" is not tunable"));
  const std::string co_simulation = std::string(kOscillator) + "\n  interface: FMU_CO_SIMULATION";
  scene = spec::io::LoadSceneFile(Write("c.scene.textproto", Scene(co_simulation, kPositionAndForce)));
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_THAT(FmuSensitivitiesUnavailable(*scene, {0}), HasSubstr("a Co-Simulation FMU integrates itself"));
}

}  // namespace
}  // namespace mbopt::fmu
