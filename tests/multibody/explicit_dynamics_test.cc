// Forward dynamics on the explicit Runge-Kutta path (explicit_dynamics.h):
// its agreement with IDAS, a stiff model's failure named, what it refuses
// and the scene setting that chooses it. The closed forms and published
// answers the IDAS path is held to hold it too, with the same tolerances:
// dynamics_test.cc runs them on both paths.
#include "worker/multibody/explicit_dynamics.h"

#include <cmath>
#include <iostream>
#include <numbers>
#include <optional>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/multibody/andrews_on_both_paths.h"
#include "tests/multibody/mechanisms.h"
#include "tests/multibody/time_grid.h"
#include "tests/testing/file_text.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/scene_analysis.h"

namespace mbopt::multibody {
namespace {

using testing::At;
using testing::Grid;

ForwardDynamicsOptions Explicit(double rtol, double atol) {
  ForwardDynamicsOptions options;
  options.method = ForwardDynamicsOptions::Method::kExplicitRungeKutta;
  options.relative_tolerance = rtol;
  options.absolute_tolerance = atol;
  return options;
}

// The paths agree on the Simbody comparisons' ten-rod chain at tight
// tolerances (tests/oracle holds both against Simbody itself).
TEST(MultibodyExplicitDynamics, AgreesWithIdasOnTheClosedRodChain) {
  const Model model = testing::RodChain(10);
    const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  auto run = [&](ForwardDynamicsOptions options, std::vector<Eigen::VectorXd>* q) {
    ForwardDynamicsCounters counters;
    return IntegrateForward(
        m, 0.0, assembled.q, assembled.v, Grid(2.0, 20), options,
        [&](const MotionSample& s) {
          q->push_back(s.q);
          return spec::AnalysisFailure::Ok();
        },
        &counters);
  };
  std::vector<Eigen::VectorXd> bdf, erk;
  ForwardDynamicsOptions implicit;
  implicit.relative_tolerance = implicit.absolute_tolerance = 1e-10;
  ASSERT_TRUE(run(implicit, &bdf).ok());
  const spec::AnalysisFailure f = run(Explicit(1e-10, 1e-10), &erk);
  ASSERT_TRUE(f.ok()) << f.reason;
  ASSERT_EQ(bdf.size(), erk.size());
  double worst = 0.0;
  for (size_t i = 0; i < bdf.size(); ++i) worst = std::max(worst, (bdf[i] - erk[i]).cwiseAbs().maxCoeff());
  constexpr double kAgreement = 1e-6;  // m, rad: the Simbody comparisons'
  EXPECT_LT(worst, kAgreement);
  EXPECT_GT(std::abs(erk.back()[3 * 4 + 2]), 0.1);  // the middle rods leave the horizontal
}

// A stiff spring (omega = 1e5 rad/s on unit masses) holds an explicit
// method to steps of its stability limit: the step budget ends the analysis
// with a named failure that points to IDAS, in well under a second.
TEST(MultibodyExplicitDynamics, StiffSpringEndsInANamedFailure) {
  const Model model = testing::SundialsSliderCrank(1e10, 0.0);
    const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  ForwardDynamicsOptions options = Explicit(1e-6, 1e-8);
  options.max_steps = 2000;
  ForwardDynamicsCounters counters;
  const spec::AnalysisFailure f = IntegrateForward(
      m, 0.0, assembled.q, assembled.v, Grid(1.0, 10), options,
      [](const MotionSample&) { return spec::AnalysisFailure::Ok(); }, &counters);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.kind, spec::FailureKind::kIntegrator);
  EXPECT_NE(f.reason.find("explicit Runge-Kutta"), std::string::npos) << f.reason;
  EXPECT_NE(f.reason.find("stiff"), std::string::npos) << f.reason;
  EXPECT_LE(counters.steps, 2000);
}

TEST(MultibodyExplicitDynamics, RefusesSimulatorSensitivities) {
  const Model model = testing::Pendulum(1.0, 1.0, 0.5);
    const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  ForwardSensitivityInput input;
  input.parameters.push_back(ParameterPerturbation{&m, &m, 1e-6, 1.0, nullptr});
  input.q0.push_back(Eigen::VectorXd::Zero(3));
  input.v0.push_back(Eigen::VectorXd::Zero(3));
  ForwardDynamicsCounters counters;
  const spec::AnalysisFailure f = IntegrateForward(
      m, 0.0, assembled.q, assembled.v, Grid(1.0, 10), Explicit(1e-6, 1e-9),
      [](const MotionSample&) { return spec::AnalysisFailure::Ok(); }, &counters, &input);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.kind, spec::FailureKind::kInvalidModel);
  EXPECT_NE(f.reason.find("sensitivities"), std::string::npos) << f.reason;
}

// A scene chooses the path by `integrator { method: EXPLICIT_RUNGE_KUTTA }`:
// Andrews' mechanism analysed whole on it gives the IDAS analysis' outputs
// (the seven angles at every millisecond) within both runs' errors at rtol
// 1e-8 (each about 3e-7 rad from its reference, bench_multibody_workprec).
TEST(MultibodyExplicitDynamics, SceneSettingChoosesThePathForAWholeAnalysis) {
  const std::optional<testing::ScenesOnBothPaths> scenes = testing::AndrewsOnBothPaths();
  ASSERT_TRUE(scenes.has_value());
  const spec::Scene* bdf = &scenes->idas;
  const spec::Scene* erk = &scenes->explicit_path;
  EXPECT_EQ(bdf->integrator.method, spec::IntegratorMethod::kIdas);
  EXPECT_EQ(erk->integrator.method, spec::IntegratorMethod::kExplicitRungeKutta);
  const spec::AnalysisReport a = AnalyzeMultibodyScene(*bdf, bdf->DefaultParameterValues(), nullptr);
  const spec::AnalysisReport b = AnalyzeMultibodyScene(*erk, erk->DefaultParameterValues(), nullptr);
  ASSERT_TRUE(a.ok()) << a.failure.reason;
  ASSERT_TRUE(b.ok()) << b.failure.reason;
  ASSERT_EQ(a.outputs.size(), b.outputs.size());
  double worst = 0.0;
  for (size_t k = 0; k < a.outputs.size(); ++k) {
    ASSERT_EQ(a.outputs[k].series.size(), b.outputs[k].series.size());
    for (size_t s = 0; s < a.outputs[k].series.size(); ++s) {
      ASSERT_EQ(a.outputs[k].series[s].size(), 31u);
      ASSERT_EQ(b.outputs[k].series[s].size(), 31u);
      for (size_t i = 0; i < 31; ++i) {
        worst = std::max(worst, std::abs(a.outputs[k].series[s][i] - b.outputs[k].series[s][i]));
      }
    }
  }
  constexpr double kAgreement = 2e-6;  // rad
  EXPECT_LT(worst, kAgreement);
  // Not the same integration: the explicit path takes far fewer steps.
  EXPECT_LT(b.counters.time_steps, a.counters.time_steps / 2);
  std::cout << "Andrews, scene on each path: largest difference " << worst << " rad, steps "
            << a.counters.time_steps << " (IDAS) and " << b.counters.time_steps << " (explicit)\n";
}

// The scene's text with the explicit method in its integrator settings.
std::string WithExplicitMethod(std::string text) {
  const std::string block = "integrator {";
  const size_t at = text.find(block);
  if (at == std::string::npos) return text + "\nintegrator { method: EXPLICIT_RUNGE_KUTTA }\n";
  return text.insert(at + block.size(), " method: EXPLICIT_RUNGE_KUTTA");
}

TEST(MultibodyExplicitDynamics, SceneLoaderRefusesItWhereItDoesNotApply) {
  // A lumped model has its own integrator (CVODES).
  const std::string vehicle = mbopt::testing::FileText("examples/vehicle/vehicle.scene.textproto");
  ASSERT_TRUE(spec::io::ParseSceneText(vehicle, "vehicle.textproto").ok());
  absl::StatusOr<spec::Scene> lumped = spec::io::ParseSceneText(WithExplicitMethod(vehicle), "vehicle.textproto");
  ASSERT_FALSE(lumped.ok());
  EXPECT_NE(lumped.status().message().find("`multibody` and `spatial` scenes only"), std::string::npos)
      << lumped.status();
  // Flexible links are stiff.
  const std::string flexible = mbopt::testing::FileText("examples/fourbar/fourbar_corotational.scene.textproto");
  ASSERT_TRUE(spec::io::ParseSceneText(flexible, "fourbar.textproto").ok());
  absl::StatusOr<spec::Scene> corotational =
      spec::io::ParseSceneText(WithExplicitMethod(flexible), "fourbar.textproto");
  ASSERT_FALSE(corotational.ok());
  EXPECT_NE(corotational.status().message().find("flexible links"), std::string::npos) << corotational.status();
}

// A study asking for simulator sensitivities of a scene on the explicit
// path is refused when it is loaded, not analysis by analysis.
TEST(MultibodyExplicitDynamics, StudyLoaderRefusesSimulatorSensitivitiesOnIt) {
  std::string study = mbopt::testing::FileText("examples/isolator/isolator_sensitivity.study.textproto");
  const std::string scene = mbopt::testing::FileText("examples/isolator/isolator.scene.textproto");
  const std::string file_line = "scene_file: \"isolator.scene.textproto\"";
  const size_t at = study.find(file_line);
  ASSERT_NE(at, std::string::npos);
  const std::string plain = std::string(study).replace(at, file_line.size(), "scene {\n" + scene + "\n}");
  absl::StatusOr<v1::Study> idas = spec::io::ParseStudyText(plain, "isolator.study.textproto");
  ASSERT_TRUE(idas.ok()) << idas.status();
  const std::string with_explicit =
      study.replace(at, file_line.size(), "scene {\n" + WithExplicitMethod(scene) + "\n}");
  absl::StatusOr<v1::Study> erk = spec::io::ParseStudyText(with_explicit, "isolator.study.textproto");
  ASSERT_FALSE(erk.ok());
  EXPECT_NE(erk.status().message().find("EXPLICIT_RUNGE_KUTTA"), std::string::npos) << erk.status();
  EXPECT_NE(erk.status().message().find("SENSITIVITY_METHOD_SIMULATOR"), std::string::npos) << erk.status();
}

}  // namespace
}  // namespace mbopt::multibody
