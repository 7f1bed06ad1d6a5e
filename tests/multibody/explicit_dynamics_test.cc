// Forward dynamics on the explicit Runge-Kutta path (explicit_dynamics.h)
// against the closed forms and published answers the IDAS path is held to
// (dynamics_test.cc), with the same tolerances; the projection's drift; a
// stiff model's failure named.
#include "worker/multibody/explicit_dynamics.h"

#include <cmath>
#include <fstream>
#include <iostream>
#include <numbers>
#include <sstream>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/multibody/mechanisms.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/scene_analysis.h"

namespace mbopt::multibody {
namespace {

using testing::At;

std::vector<double> Grid(double end_s, int intervals) {
  std::vector<double> t;
  for (int i = 0; i <= intervals; ++i) t.push_back(end_s * i / intervals);
  return t;
}

ForwardDynamicsOptions Explicit(double rtol, double atol) {
  ForwardDynamicsOptions options;
  options.method = ForwardDynamicsOptions::Method::kExplicitRungeKutta;
  options.relative_tolerance = rtol;
  options.absolute_tolerance = atol;
  return options;
}

double FirstPeriod(const std::vector<double>& t, const std::vector<double>& angle) {
  for (size_t i = 2; i + 1 < angle.size(); ++i) {
    if (angle[i] >= angle[i - 1] && angle[i] > angle[i + 1]) {
      const double h = t[i] - t[i - 1];
      const double a = angle[i - 1], b = angle[i], c = angle[i + 1];
      return t[i] + 0.5 * h * (a - c) / (a - 2 * b + c);
    }
  }
  return NAN;
}

TEST(MultibodyExplicitDynamics, CompoundPendulumPeriodMatchesTheEllipticIntegral) {
  constexpr double mass = 1.5, length = 0.9, g = 9.81;
  for (double theta0 : {0.1, 1.0, 2.5}) {
    const Model model = testing::Pendulum(mass, length, theta0, g);
    const Mechanism m(model);
    const Assembly assembled = Assemble(m, 0.0);
    ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
    const double period = 4.0 * std::sqrt((length * length / 3.0) / (g * length / 2.0)) *
                          std::comp_ellint_1(std::sin(theta0 / 2.0));
    const std::vector<double> times = Grid(1.3 * period, 4000);
    std::vector<double> angle;
    ForwardDynamicsCounters counters;
    const spec::AnalysisFailure f = IntegrateForward(
        m, 0.0, assembled.q, assembled.v, times, Explicit(1e-9, 1e-11),
        [&](const MotionSample& s) {
          angle.push_back(s.q[2] + std::numbers::pi / 2);
          return spec::AnalysisFailure::Ok();
        },
        &counters);
    ASSERT_TRUE(f.ok()) << f.reason;
    constexpr double kPeriodAgreement = 1e-6;  // as for IDAS
    EXPECT_NEAR(FirstPeriod(times, angle) / period, 1.0, kPeriodAgreement) << "theta0 = " << theta0;
    // The projection after every step holds the constraints to a hundredth
    // of the absolute tolerance.
    EXPECT_LT(counters.max_position_drift, 1e-12);
    EXPECT_LT(counters.max_velocity_drift, 1e-12);
    EXPECT_GT(counters.steps, 0);
    EXPECT_GT(counters.residual_evaluations, counters.steps);
  }
}

TEST(MultibodyExplicitDynamics, FreeFallWithoutConstraints) {
  Model model;
  Body b;
  b.name = "ball";
  b.mass_kg = 0.2;
  b.inertia_kg_m2 = 1e-3;
  b.position_m = {0.0, 10.0};
  model.bodies.push_back(b);
  model.gravity_m_per_s2 = Eigen::Vector2d(0.0, -9.81);
    const Mechanism m(model);
  Eigen::VectorXd v0(3);
  v0 << 1.0, 2.0, 0.5;
  ForwardDynamicsCounters counters;
  constexpr double kFreeFallAgreement = 1e-7;
  int instants = 0;
  const spec::AnalysisFailure f = IntegrateForward(
      m, 0.0, m.InitialGuess(), v0, Grid(1.0, 10), Explicit(1e-9, 1e-11),
      [&](const MotionSample& s) {
        const double t = s.t_s;
        ++instants;
        EXPECT_NEAR(s.q[0], 1.0 * t, kFreeFallAgreement);
        EXPECT_NEAR(s.q[1], 10.0 + 2.0 * t - 0.5 * 9.81 * t * t, kFreeFallAgreement);
        EXPECT_NEAR(s.q[2], 0.5 * t, kFreeFallAgreement);
        EXPECT_NEAR(s.a[1], -9.81, 1e-12);
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  EXPECT_TRUE(f.ok()) << f.reason;
  EXPECT_EQ(instants, 11);
}

TEST(MultibodyExplicitDynamics, UndampedDoublePendulumConservesEnergyAndTheConstraints) {
  const Model model = testing::DoublePendulum(0.3, -0.4);
    const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  const double e0 = m.KineticEnergy(assembled.v) + m.PotentialEnergy(assembled.q);
  double worst = 0.0;
  ForwardDynamicsCounters counters;
  const spec::AnalysisFailure f = IntegrateForward(
      m, 0.0, assembled.q, assembled.v, Grid(10.0, 1000), Explicit(1e-8, 1e-10),
      [&](const MotionSample& s) {
        worst = std::max(worst, std::abs(m.KineticEnergy(s.v) + m.PotentialEnergy(s.q) - e0));
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  ASSERT_TRUE(f.ok()) << f.reason;
  constexpr double kEnergyDrift = 1e-5;  // J, as for IDAS
  EXPECT_LT(worst, kEnergyDrift);
  // Without the projection the index-1 ODE lets Phi drift with the
  // truncation error over 10 s of a chaotic motion; with it the drift at
  // every instant stays at a hundredth of the absolute tolerance.
  EXPECT_LT(counters.max_position_drift, 1e-12);
  EXPECT_LT(counters.max_velocity_drift, 1e-12);
  std::cout << "double pendulum (explicit): energy drift " << worst << " J over 10 s, " << counters.steps
            << " steps, drift " << counters.max_position_drift << " m\n";
}

double SundialsG(double rtol, double atol) {
  const Model model = testing::SundialsSliderCrank(1.0, 1.0);
    const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  EXPECT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  const std::vector<double> times = Grid(10.0, 10000);
  std::vector<double> energy;
  ForwardDynamicsCounters counters;
  const spec::AnalysisFailure f = IntegrateForward(
      m, 0.0, assembled.q, assembled.v, times, Explicit(rtol, atol),
      [&](const MotionSample& s) {
        energy.push_back(m.KineticEnergy(s.v));
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  EXPECT_TRUE(f.ok()) << f.reason;
  if (!f.ok()) return NAN;
  const double h = times[1] - times[0];
  double g = energy.front() + energy.back();
  for (size_t i = 1; i + 1 < energy.size(); ++i) g += (i % 2 == 1 ? 4.0 : 2.0) * energy[i];
  return g * h / 3.0;
}

TEST(MultibodyExplicitDynamics, SundialsSliderCrankKineticEnergyIntegralMatchesThePublishedAnswer) {
  constexpr double kPublishedG = 3.3366157997761721;
  constexpr double kAtExampleTolerances = 2e-5;  // as for IDAS (dynamics_test.cc)
  constexpr double kTight = 1e-5;
  EXPECT_NEAR(SundialsG(1e-6, 1e-7) / kPublishedG, 1.0, kAtExampleTolerances);
  EXPECT_NEAR(SundialsG(1e-10, 1e-12) / kPublishedG, 1.0, kTight);
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

TEST(MultibodyExplicitDynamics, RedundantJointsAtTheStartAreANamedFailure) {
  Model model = testing::Pendulum(1.0, 1.0, 0.5);
  model.joints.push_back(testing::Revolute("pin twice", At(kGround, 0.0), At(0, -0.5)));
    const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  ForwardDynamicsCounters counters;
  const spec::AnalysisFailure f = IntegrateForward(
      m, 0.0, assembled.q, assembled.v, Grid(1.0, 10), Explicit(1e-6, 1e-9),
      [](const MotionSample&) { return spec::AnalysisFailure::Ok(); }, &counters);
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.reason.find("redundant joints"), std::string::npos) << f.reason;
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

std::string FileText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A scene chooses the path by `integrator { method: EXPLICIT_RUNGE_KUTTA }`:
// Andrews' mechanism analysed whole on it gives the IDAS analysis' outputs
// (the seven angles at every millisecond) within both runs' errors at rtol
// 1e-8 (each about 3e-7 rad from its reference, bench_multibody_workprec).
TEST(MultibodyExplicitDynamics, SceneSettingChoosesThePathForAWholeAnalysis) {
  const std::string text = FileText("examples/andrews/andrews.scene.textproto");
  ASSERT_FALSE(text.empty());
  const std::string tolerances = " relative_tolerance: 1e-8 absolute_tolerance: 1e-10 }\n";
  absl::StatusOr<spec::Scene> bdf = spec::io::ParseSceneText(text + "integrator {" + tolerances, "andrews.textproto");
  absl::StatusOr<spec::Scene> erk = spec::io::ParseSceneText(
      text + "integrator { method: EXPLICIT_RUNGE_KUTTA" + tolerances, "andrews.textproto");
  ASSERT_TRUE(bdf.ok()) << bdf.status();
  ASSERT_TRUE(erk.ok()) << erk.status();
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
  const std::string vehicle = FileText("examples/vehicle/vehicle.scene.textproto");
  ASSERT_TRUE(spec::io::ParseSceneText(vehicle, "vehicle.textproto").ok());
  absl::StatusOr<spec::Scene> lumped = spec::io::ParseSceneText(WithExplicitMethod(vehicle), "vehicle.textproto");
  ASSERT_FALSE(lumped.ok());
  EXPECT_NE(lumped.status().message().find("`multibody` and `spatial` scenes only"), std::string::npos)
      << lumped.status();
  // Flexible links are stiff.
  const std::string flexible = FileText("examples/fourbar/fourbar_corotational.scene.textproto");
  ASSERT_TRUE(spec::io::ParseSceneText(flexible, "fourbar.textproto").ok());
  absl::StatusOr<spec::Scene> corotational =
      spec::io::ParseSceneText(WithExplicitMethod(flexible), "fourbar.textproto");
  ASSERT_FALSE(corotational.ok());
  EXPECT_NE(corotational.status().message().find("flexible links"), std::string::npos) << corotational.status();
}

// A study asking for simulator sensitivities of a scene on the explicit
// path is refused when it is loaded, not analysis by analysis.
TEST(MultibodyExplicitDynamics, StudyLoaderRefusesSimulatorSensitivitiesOnIt) {
  std::string study = FileText("examples/isolator/isolator_sensitivity.study.textproto");
  const std::string scene = FileText("examples/isolator/isolator.scene.textproto");
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
