// Static equilibrium against closed forms (virtual work), its stability
// test, and the scene-level contract: the formulation, the counters (no time
// step, no mass matrix) and the outputs a static analysis refuses.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/multibody/mechanisms.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/scene_analysis.h"
#include "worker/multibody/static_equilibrium.h"

namespace mbopt::multibody {
namespace {

using ::testing::HasSubstr;
using testing::At;
using testing::Bar;
using testing::Revolute;

struct Solved {
  spec::AnalysisFailure failure;
  std::vector<MotionSample> samples;
  StaticCounters counters;
};

Solved SolveStatic(const Mechanism& mechanism, const std::vector<double>& times,
                   const StaticOptions& options = StaticOptions{}) {
  Solved out;
  const Assembly assembled = Assemble(mechanism, times.front());
  EXPECT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  out.failure = RunStaticEquilibrium(
      mechanism, assembled.q, times, options,
      [&](const MotionSample& s) {
        out.samples.push_back(s);
        return spec::AnalysisFailure::Ok();
      },
      &out.counters);
  return out;
}

// A uniform bar (m, L) pinned at one end to ground, with a rotational spring
// k at the pin (free angle 0: horizontal), under gravity: equilibrium where
// k theta = -m g (L/2) cos theta (theta from the horizontal). The pin carries
// the weight: reaction (0, m g) on the bar.
TEST(MultibodyStatics, SpringLoadedBarBalancesItsWeight) {
  const double m = 2.0, length = 0.8, k = 20.0, g = 9.81;
  Model model;
  model.bodies.push_back(Bar("bar", m, length, {length / 2, 0.0}, 0.0));
  model.joints.push_back(Revolute("pin", At(kGround, 0.0), At(0, -length / 2)));
  model.rotational_springs.push_back(RotationalSpringDamper{"spring", 0, k, 0.0, 0.0});
  model.gravity_m_per_s2 = Eigen::Vector2d(0.0, -g);
  ASSERT_TRUE(model.Validate().ok());
  const Mechanism mechanism(model);
  const Solved solved = SolveStatic(mechanism, {0.0});
  ASSERT_TRUE(solved.failure.ok()) << solved.failure.reason;
  ASSERT_EQ(solved.samples.size(), 1u);

  // Reference: scalar Newton on k th + m g L/2 cos th = 0.
  double theta = 0.0;
  for (int i = 0; i < 50; ++i) {
    const double f = k * theta + m * g * length / 2 * std::cos(theta);
    const double df = k - m * g * length / 2 * std::sin(theta);
    theta -= f / df;
  }
  const MotionSample& s = solved.samples[0];
  EXPECT_NEAR(mechanism.JointCoordinate(0, s.q), theta, 1e-10);
  EXPECT_LT(theta, -0.3);  // a real deflection, not the start
  // -Phi_q^T lambda on the bar's x, y: the force ground exerts on it.
  Eigen::MatrixXd phi_q;
  mechanism.ConstraintJacobian(0.0, s.q, &phi_q);
  const Eigen::Vector2d reaction = -phi_q.block(0, 0, 2, 2).transpose() * s.lambda.head(2);
  EXPECT_NEAR(reaction.x(), 0.0, 1e-9);
  EXPECT_NEAR(reaction.y(), m * g, 1e-9);
  EXPECT_GT(solved.counters.newton_iterations, 0);
  EXPECT_EQ(solved.counters.position_solves, 1);
  EXPECT_EQ(mechanism.counters().mass_matrix_evaluations, 0);
}

// A body on a vertical slide hung from a spring (k, free length L0) from a
// ground point above: it settles m g / k below the free length.
TEST(MultibodyStatics, HangingMassStretchesItsSpringByWeightOverStiffness) {
  const double m = 3.0, k = 1500.0, free_length = 0.5, g = 9.81;
  Model model;
  Body block;
  block.name = "block";
  block.mass_kg = m;
  block.inertia_kg_m2 = 0.01;
  block.position_m = {0.0, -0.4};
  model.bodies.push_back(block);
  Joint slide;
  slide.name = "slide";
  slide.kind = JointKind::kPrismatic;
  slide.a = At(kGround, 0.0);
  slide.b = At(0, 0.0);
  slide.axis_angle_rad = std::numbers::pi / 2;
  model.joints.push_back(slide);
  SpringDamper spring;
  spring.name = "spring";
  spring.a = At(kGround, 0.0, 0.0);
  spring.b = At(0, 0.0);
  spring.free_length_m = free_length;
  spring.stiffness_n_per_m = k;
  model.springs.push_back(spring);
  model.gravity_m_per_s2 = Eigen::Vector2d(0.0, -g);
  ASSERT_TRUE(model.Validate().ok());
  const Mechanism mechanism(model);
  const Solved solved = SolveStatic(mechanism, {0.0});
  ASSERT_TRUE(solved.failure.ok()) << solved.failure.reason;
  EXPECT_NEAR(solved.samples[0].q[1], -(free_length + m * g / k), 1e-12);
  EXPECT_NEAR(mechanism.SpringTension(0, solved.samples[0].q, solved.samples[0].v), m * g, 1e-9);
}

// A driven slider-crank held against a constant force P on the slider: by
// virtual work the static driver torque is T = -F_x dx/dth with
// dx/dth = -r sin th - r^2 sin th cos th / sqrt(l^2 - r^2 sin^2 th), at every
// crank angle along the driven motion (no inertia in a static analysis).
TEST(MultibodyStatics, SliderCrankDriverTorqueIsTheVirtualWorkOfTheLoad) {
  const double r = 0.1, l = 0.35, omega = 2.0, force = -250.0;
  Model model = testing::SliderCrank(r, l, omega);
  model.point_forces.push_back(PointForce{At(2, 0.0), Eigen::Vector2d(force, 0.0), std::nullopt});
  model.gravity_m_per_s2 = Eigen::Vector2d(0.0, -9.81);  // balanced by the pin and the slide: no torque
  ASSERT_TRUE(model.Validate().ok());
  const Mechanism mechanism(model);
  std::vector<double> times;
  for (int i = 0; i <= 30; ++i) times.push_back(0.1 * i);
  const Solved solved = SolveStatic(mechanism, times);
  ASSERT_TRUE(solved.failure.ok()) << solved.failure.reason;
  ASSERT_EQ(solved.samples.size(), times.size());
  const int driver_row = mechanism.row_of_driver(0);
  double worst = 0.0;
  for (const MotionSample& s : solved.samples) {
    const double th = omega * s.t_s;
    const double root = std::sqrt(l * l - r * r * std::sin(th) * std::sin(th));
    const double dx = -r * std::sin(th) - r * r * std::sin(th) * std::cos(th) / root;
    // Weight of the crank and rod also does virtual work: their centres
    // drop by d(y)/dth.
    const double dy_crank = 0.5 * r * std::cos(th);
    const double dy_rod = 0.5 * r * std::cos(th);  // the rod's centre is midway between tip and slider (y = 0)
    const double expected = -force * dx + 9.81 * (1.0 * dy_crank + 2.0 * dy_rod);
    worst = std::max(worst, std::abs(-s.lambda[driver_row] - expected));
  }
  EXPECT_LT(worst, 1e-8);
  EXPECT_EQ(solved.counters.position_solves, static_cast<long>(times.size()));
}

// KINSOL's Newton matrix is the analytic one where the mechanism's
// derivatives are exact (EquilibriumJacobian): it matches central
// differences of the equilibrium equations away from an equilibrium, and a
// slider-crank held by a spring and a force comes to the same 31
// equilibria as with KINSOL's difference quotients (to 1e-9), for fewer
// residual evaluations.
TEST(MultibodyStatics, KinsolGetsTheAnalyticNewtonMatrix) {
  const double r = 0.1, l = 0.35, omega = 2.0;
  Model model = testing::SliderCrank(r, l, omega);
  model.point_forces.push_back(PointForce{At(2, 0.0), Eigen::Vector2d(-250.0, 0.0), std::nullopt});
  SpringDamper spring;
  spring.name = "spring";
  spring.a = At(kGround, 0.0, 0.2);
  spring.b = At(1, 0.1);
  spring.free_length_m = 0.1;
  spring.stiffness_n_per_m = 800.0;
  model.springs.push_back(spring);
  model.gravity_m_per_s2 = Eigen::Vector2d(0.0, -9.81);
  ASSERT_TRUE(model.Validate().ok());
  const Mechanism mechanism(model);
  ASSERT_TRUE(mechanism.has_exact_state_jacobian());
  std::vector<double> times;
  for (int i = 0; i <= 30; ++i) times.push_back(0.1 * i);
  StaticOptions differenced;
  differenced.analytic_newton_matrix = false;
  const Solved analytic = SolveStatic(mechanism, times), quotients = SolveStatic(mechanism, times, differenced);
  ASSERT_TRUE(analytic.failure.ok()) << analytic.failure.reason;
  ASSERT_TRUE(quotients.failure.ok()) << quotients.failure.reason;
  ASSERT_EQ(analytic.samples.size(), times.size());
  ASSERT_EQ(quotients.samples.size(), times.size());
  for (size_t i = 0; i < times.size(); ++i) {
    const MotionSample &a = analytic.samples[i], &d = quotients.samples[i];
    for (int k = 0; k < a.q.size(); ++k) EXPECT_NEAR(a.q[k], d.q[k], 1e-9) << "t = " << a.t_s << ", q" << k;
    for (int k = 0; k < a.lambda.size(); ++k) {
      EXPECT_NEAR(a.lambda[k], d.lambda[k], 1e-9 * std::max(1.0, std::abs(d.lambda[k])))
          << "t = " << a.t_s << ", lambda" << k;
    }
  }
  EXPECT_GT(analytic.counters.newton_matrices, 0);
  EXPECT_EQ(quotients.counters.newton_matrices, 0);
  EXPECT_LT(analytic.counters.residual_evaluations, quotients.counters.residual_evaluations);
  std::cout << "residual evaluations: " << analytic.counters.residual_evaluations << " analytic ("
            << analytic.counters.newton_matrices << " matrices), " << quotients.counters.residual_evaluations
            << " with difference quotients; Newton iterations " << analytic.counters.newton_iterations << " and "
            << quotients.counters.newton_iterations << "\n";

  // Off the equilibrium: G(q, lambda) = (Q(t, q, 0) - Phi_q^T lambda, Phi(t, q)).
  const int n = mechanism.num_coordinates(), m = mechanism.num_constraints();
  const double t = times[7];
  Eigen::VectorXd q = analytic.samples[7].q, lambda = analytic.samples[7].lambda;
  for (int k = 0; k < n; ++k) q[k] += 1e-3 * (k + 1);
  for (int k = 0; k < m; ++k) lambda[k] += 10.0 * (k + 1);
  auto equations = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd forces, phi;
    Eigen::MatrixXd phi_q;
    const Eigen::VectorXd qx = x.head(n);
    EXPECT_EQ(mechanism.AppliedForces(t, qx, Eigen::VectorXd::Zero(n), &forces), 0);
    EXPECT_EQ(mechanism.ConstraintJacobian(t, qx, &phi_q), 0);
    EXPECT_EQ(mechanism.Constraints(t, qx, &phi), 0);
    Eigen::VectorXd g(n + m);
    g.head(n) = forces - phi_q.transpose() * x.tail(m);
    g.tail(m) = phi;
    return g;
  };
  Eigen::MatrixXd jacobian;
  ASSERT_TRUE(EquilibriumJacobian(mechanism, t, q, lambda, &jacobian));
  Eigen::VectorXd x(n + m);
  x << q, lambda;
  const double scale = jacobian.cwiseAbs().maxCoeff();
  for (int k = 0; k < n + m; ++k) {
    const double h = 1e-6 * std::max(1.0, std::abs(x[k]));
    Eigen::VectorXd plus = x, minus = x;
    plus[k] += h;
    minus[k] -= h;
    const Eigen::VectorXd column = (equations(plus) - equations(minus)) / (2 * h);
    EXPECT_LT((column - jacobian.col(k)).cwiseAbs().maxCoeff(), 1e-6 * scale) << "column " << k;
  }
}

// An inverted pendulum is in equilibrium straight up, but not a stable one.
TEST(MultibodyStatics, UnstableEquilibriumIsAFailedAnalysisNamingTheTime) {
  Model model = testing::Pendulum(1.0, 1.0, std::numbers::pi);  // straight up
  const Mechanism mechanism(model);
  const Solved solved = SolveStatic(mechanism, {0.0});
  ASSERT_FALSE(solved.failure.ok());
  EXPECT_EQ(solved.failure.kind, spec::FailureKind::kModelValidity);
  EXPECT_THAT(solved.failure.reason, HasSubstr("unstable"));
  EXPECT_THAT(solved.failure.reason, HasSubstr("t = 0"));
}

// Hanging down, the same pendulum is stable and found from 60 degrees off.
TEST(MultibodyStatics, PendulumSettlesStraightDownFromAnAngle) {
  Model model = testing::Pendulum(1.0, 1.0, std::numbers::pi / 3);
  const Mechanism mechanism(model);
  const Solved solved = SolveStatic(mechanism, {0.0});
  ASSERT_TRUE(solved.failure.ok()) << solved.failure.reason;
  EXPECT_NEAR(solved.samples[0].q[0], 0.0, 1e-10);
  EXPECT_NEAR(solved.samples[0].q[1], -0.5, 1e-10);
}

// No equilibrium exists: a free body under gravity with nothing to hold it.
TEST(MultibodyStatics, NoEquilibriumIsAFailedAnalysis) {
  Model model;
  model.bodies.push_back(Bar("stone", 1.0, 0.1, {0.0, 0.0}, 0.0));
  model.gravity_m_per_s2 = Eigen::Vector2d(0.0, -9.81);
  const Mechanism mechanism(model);
  const Solved solved = SolveStatic(mechanism, {0.0});
  ASSERT_FALSE(solved.failure.ok());
  EXPECT_EQ(solved.failure.kind, spec::FailureKind::kAssembly);
  EXPECT_THAT(solved.failure.reason, HasSubstr("no static equilibrium found at t = 0"));
}

constexpr char kStaticArmScene[] = R"pb(
name: "arm"
parameters { name: "k" value: 20 }
effects { gravity { acceleration_m_per_s2 { x { value: 0 } y { value: -9.81 } } } }
multibody {
  analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM
  bodies {
    name: "arm"
    mass_kg { value: 2 }
    inertia_kg_m2 { value: 0.1067 }
    position_m { x { value: 0.4 } }
    markers { name: "pin" position_m { x { value: -0.4 } } }
  }
  joints { name: "pin" kind: JOINT_REVOLUTE a: "ground.origin" b: "arm.pin" }
  ground_markers { name: "origin" }
  rotational_springs { name: "spring" joint: "pin" stiffness_n_m_per_rad { param: "k" } }
}
outputs { name: "angle" joint_coordinate { joint: "pin" } }
outputs { name: "pin_y" joint_reaction { joint: "pin" axis: AXIS_Y } }
%s
time_grid { start_s: 0 end_s: 0 points: 1 }
)pb";

std::string WriteScene(const std::string& extra_output) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("mbopt_static_" + std::to_string(::getpid()) + ".textproto");
  std::string text(kStaticArmScene);
  text.replace(text.find("%s"), 2, extra_output);
  std::ofstream(path) << text;
  return path.string();
}

TEST(MultibodyStatics, SceneDeclaresTheAnalysisAndComputesNoMotion) {
  const std::string path = WriteScene("");
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(scene.ok()) << scene.status();
  const spec::AnalysisReport report = AnalyzeMultibodyScene(*scene, {20.0});
  ASSERT_TRUE(report.ok()) << report.failure.reason;
  EXPECT_EQ(report.formulation, spec::Formulation::kStatic);
  EXPECT_EQ(report.counters.time_steps, 0);
  EXPECT_EQ(report.counters.position_solves, 1);
  EXPECT_GT(report.counters.newton_iterations, 0);
  EXPECT_NEAR(report.outputs[1].series[0][0], 2.0 * 9.81, 1e-9);
  EXPECT_LT(report.outputs[0].series[0][0], -0.3);
}

TEST(MultibodyStatics, SceneRefusesRatesInAStaticAnalysis) {
  const std::string path = WriteScene(R"(outputs { name: "energy" kinetic_energy {} })");
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile(path);
  std::filesystem::remove(path);
  ASSERT_FALSE(scene.ok());
  EXPECT_THAT(std::string(scene.status().message()), HasSubstr("static-equilibrium analysis has no motion"));
  EXPECT_THAT(std::string(scene.status().message()), HasSubstr("energy"));
}

// The spring-loaded arm with its spring stiffness, its mass and its length
// (markers, centre and inertia through expressions) as parameters.
constexpr char kStaticArmDesignScene[] = R"pb(
name: "arm design"
parameters { name: "k" value: 20 }
parameters { name: "mass" value: 2 }
parameters { name: "length" value: 0.8 }
effects { gravity { acceleration_m_per_s2 { x { value: 0 } y { value: -9.81 } } } }
multibody {
  analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM
  bodies {
    name: "arm"
    mass_kg { param: "mass" }
    inertia_kg_m2 { expr: "mass * length^2 / 12" }
    position_m { x { expr: "length / 2" } }
    markers { name: "pin" position_m { x { expr: "-length / 2" } } }
    markers { name: "tip" position_m { x { expr: "length / 2" } } }
  }
  joints { name: "pin" kind: JOINT_REVOLUTE a: "ground.origin" b: "arm.pin" }
  ground_markers { name: "origin" }
  rotational_springs { name: "spring" joint: "pin" stiffness_n_m_per_rad { param: "k" } }
}
outputs { name: "angle" joint_coordinate { joint: "pin" } }
outputs { name: "pin_x" joint_reaction { joint: "pin" axis: AXIS_X } }
outputs { name: "pin_y" joint_reaction { joint: "pin" axis: AXIS_Y } }
outputs { name: "tip_y" marker_position { marker: "arm.tip" axis: AXIS_Y } }
time_grid { start_s: 0 end_s: 0 points: 1 }
)pb";

// Whole analyses with parameter i moved up and down by h, for central
// differences.
std::pair<spec::AnalysisReport, spec::AnalysisReport> AnalysesAround(const spec::Scene& scene,
                                                                     const std::vector<double>& p, size_t i, double h) {
  std::vector<double> plus = p, minus = p;
  plus[i] += h;
  minus[i] -= h;
  return {AnalyzeMultibodyScene(scene, plus), AnalyzeMultibodyScene(scene, minus)};
}

// Simulator sensitivities of a static equilibrium (the implicit function
// theorem at the solution) against central differences of whole analyses
// (step 1e-5 of each value: truncation about 1e-10, the equilibrium solved
// to 1e-10), for a stiffness and a mass (exact partials) and a length set
// through expressions (differenced partials).
TEST(MultibodyStatics, SensitivitiesAgreeWithCentralDifferencesOfWholeAnalyses) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("mbopt_static_design_" + std::to_string(::getpid()) + ".textproto");
  std::ofstream(path) << kStaticArmDesignScene;
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile(path.string());
  std::filesystem::remove(path);
  ASSERT_TRUE(scene.ok()) << scene.status();
  EXPECT_EQ(MultibodySensitivityUnavailable(*scene), "");
  const std::vector<double> p = {20.0, 2.0, 0.8};
  const MultibodySensitivityResult result = AnalyzeMultibodySceneWithSensitivities(*scene, p, {0, 1, 2});
  ASSERT_TRUE(result.report.ok()) << result.report.failure.reason;
  ASSERT_EQ(result.unavailable, "");
  ASSERT_EQ(result.output_derivatives.size(), 3u);
  for (size_t i = 0; i < p.size(); ++i) {
    const double h = 1e-5 * p[i];
    const auto [up, down] = AnalysesAround(*scene, p, i, h);
    ASSERT_TRUE(up.ok() && down.ok());
    for (size_t o = 0; o < up.outputs.size(); ++o) {
      const double fd = (up.outputs[o].series[0][0] - down.outputs[o].series[0][0]) / (2 * h);
      const double simulator = result.output_derivatives[i][o][0][0];
      EXPECT_NEAR(simulator, fd, 1e-6 * std::max(1.0, std::abs(fd)))
          << scene->parameters[i].name << " -> " << scene->outputs[o].name;
      std::cout << scene->parameters[i].name << " -> " << scene->outputs[o].name << ": " << simulator
                << ", differences " << fd << "\n";
    }
  }
  // The angle moves with every parameter (not a trivially zero derivative).
  for (size_t i = 0; i < p.size(); ++i) EXPECT_GT(std::abs(result.output_derivatives[i][0][0][0]), 1e-3);
}

// The knee scene of bench_multibody_sensitivity: 101 equilibria under a
// growing load, two exact partials (the knee spring, the strut) and one
// differenced (the thigh's length), every output against central
// differences of whole analyses at every instant, to 1e-6 of the output's
// largest derivative. A study may ask for simulator sensitivities of it.
TEST(MultibodyStatics, LoadedArmSensitivitiesAgreeAtEveryInstant) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile("tests/multibody/knee_statics.scene.textproto");
  ASSERT_TRUE(scene.ok()) << scene.status();
  std::vector<double> p;
  std::vector<int> indices;
  for (const spec::Parameter& parameter : scene->parameters) {
    indices.push_back(static_cast<int>(p.size()));
    p.push_back(parameter.value_si);
  }
  const MultibodySensitivityResult result = AnalyzeMultibodySceneWithSensitivities(*scene, p, indices);
  ASSERT_TRUE(result.report.ok()) << result.report.failure.reason;
  ASSERT_EQ(result.unavailable, "");
  double worst = 0.0;
  for (size_t i = 0; i < p.size(); ++i) {
    const double h = 1e-5 * p[i];
    const auto [up, down] = AnalysesAround(*scene, p, i, h);
    ASSERT_TRUE(up.ok() && down.ok());
    for (size_t o = 0; o < up.outputs.size(); ++o) {
      const std::vector<double>& d = result.output_derivatives[i][o][0];
      ASSERT_EQ(d.size(), up.outputs[o].series[0].size());
      double scale = 0.0, difference = 0.0;
      for (size_t t = 0; t < d.size(); ++t) {
        const double fd = (up.outputs[o].series[0][t] - down.outputs[o].series[0][t]) / (2 * h);
        scale = std::max(scale, std::abs(fd));
        difference = std::max(difference, std::abs(d[t] - fd));
      }
      std::cout << scene->parameters[i].name << " -> " << scene->outputs[o].name << ": max |d| " << scale
                << ", difference " << difference << "\n";
      if (scale > 0.0) worst = std::max(worst, difference / scale);
    }
  }
  EXPECT_LT(worst, 1e-6);
}

// A study may ask for simulator sensitivities of a static-equilibrium scene
// (the loader refused it before they existed).
TEST(MultibodyStatics, StudyMayAskForSimulatorSensitivities) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("mbopt_static_study_" + std::to_string(::getpid()) + ".textproto");
  std::ofstream(path) << "name: \"knee\"\nscene_file: \""
                      << std::filesystem::absolute("tests/multibody/knee_statics.scene.textproto").string()
                      << "\"\n"
                         "variables { name: \"k\" parameter: \"knee_stiffness\" initial: 300 lower: 100 upper: 900 }\n"
                         "objective { minimize_max_of: \"strut_force\" reduction: REDUCTION_MAX_ABS }\n"
                         "optimizer { sensitivity: SENSITIVITY_METHOD_SIMULATOR }\n";
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile(path.string());
  std::filesystem::remove(path);
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_TRUE(study->optimizer.simulator_sensitivities);
}

}  // namespace
}  // namespace mbopt::multibody
