// Simulator sensitivities of flexible links' bending stresses (one series
// per node) against central differences of whole analyses: a cantilever
// propped by a spring at its tip in static equilibrium (the implicit
// function theorem; also against equilibria closed to round-off), a beam
// bent by a driven slider (kinematics: the differentiated constraint
// equations), and a swinging flexible pendulum with structural damping
// (IDAS forward sensitivities). The parameters include the
// section's area and modulus, which change the stress at a fixed state
// (fibre distance, stiffness) as well as the state itself.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/scene_analysis.h"
#include "worker/multibody/static_equilibrium.h"

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

// One element of the steel rod clamped at the wall, its tip clamped to a
// slider that a driver moves across the rod (1 mm/s): every coordinate
// follows from the joints, so the analysis is kinematic, and the rod bends
// as a fixed-guided beam (root moment 6 EI delta / L^2).
constexpr char kGuidedBeam[] = R"pb(
name: "guided_beam"
parameters { name: "A" value: 1e-4 unit: "m^2" }
parameters { name: "E" value: 2e11 unit: "Pa" }
parameters { name: "L" value: 1 unit: "m" }
parameters { name: "rate" value: 1e-3 unit: "m/s" }
multibody {
  ground_markers { name: "wall" }
  ground_markers { name: "guide" position_m { x { param: "L" } } }
  flexible_links {
    name: "rod"
    length_m { param: "L" }
    section { area_m2 { param: "A" } youngs_modulus_pa { param: "E" } density_kg_per_m3 { value: 7800 } }
    elements: 1
  }
  bodies {
    name: "slider"
    mass_kg { value: 1 }
    inertia_kg_m2 { value: 0.01 }
    position_m { x { param: "L" } }
    markers { name: "pin" }
  }
  joints { name: "clamp" kind: JOINT_FIXED a: "ground.wall" b: "rod.a" }
  joints { name: "tip" kind: JOINT_FIXED a: "slider.pin" b: "rod.b" }
  joints {
    name: "guide" kind: JOINT_PRISMATIC a: "ground.guide" b: "slider.pin"
    axis_angle_rad { value: 1.5707963267948966 }
  }
  drivers { joint: "guide" constant_rate { start { value: 0 } rate { param: "rate" } } }
}
outputs { name: "tip_y" marker_position { marker: "rod.b" axis: AXIS_Y } }
outputs { name: "stress" bending_stress { link: "rod" } }
time_grid { start_s: 0.5 end_s: 1 points: 3 }
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
      // Every stress derivative here is far from zero: a missing term
      // would show.
      if (d.size() > 1) {
        EXPECT_GT(scale, 0.0) << scene.parameters[i].name << " -> " << scene.outputs[o].name;
      }
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
  const double area = 1e-4, inertia = area * area / (4 * std::numbers::pi), tip_stiffness = 3 * 2e11 * inertia;
  const double root = -10.0 * (tip_stiffness / (500.0 + tip_stiffness)) * std::sqrt(area / std::numbers::pi) / inertia;
  EXPECT_NEAR(report.outputs[1].series[0][0] / root, 1.0, 1e-3);
  // Measured: 4.0e-6, the tip deflection's derivatives too, and the same
  // at steps 1e-5 and 1e-4: the whole analyses' equilibria stop at the
  // solver's tolerance, and that error moves with the parameters (the next
  // test takes it out).
  const double worst = WorstRelativeDifference(*scene, 1e-4);
  std::cout << "worst relative difference " << worst << "\n";
  EXPECT_LT(worst, 1e-5);
}

// The root's stress and the tip's deflection of an equilibrium closed to
// round-off: the static solve's equilibrium and three more Newton steps
// with the implicit function theorem's matrix.
struct Polished {
  double root_stress_pa = NAN, tip_y_m = NAN;
};
Polished PolishedEquilibrium(const spec::Scene& scene, const std::vector<double>& p) {
  absl::StatusOr<Model> model = CompileModel(scene, p);
  EXPECT_TRUE(model.ok()) << model.status();
  if (!model.ok()) return {};
  const Mechanism m(*model);
  const Assembly assembled = Assemble(m, 0.0);
  EXPECT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  Eigen::VectorXd q, lambda;
  StaticCounters counters;
  const spec::AnalysisFailure f = RunStaticEquilibrium(
      m, assembled.q, {0.0}, StaticOptions{},
      [&](const MotionSample& s) {
        q = s.q;
        lambda = s.lambda;
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  EXPECT_TRUE(f.ok()) << f.reason;
  const int n = m.num_coordinates(), rows = m.num_constraints();
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  for (int iteration = 0; iteration < 3; ++iteration) {
    Eigen::MatrixXd force_q, force_v, phi_q, curvature;
    Eigen::VectorXd force, phi;
    m.ForceJacobians(0.0, q, zero, &force_q, &force_v);
    m.ConstraintJacobian(0.0, q, &phi_q);
    m.ConstraintCurvature(0.0, q, lambda, &curvature);
    m.AppliedForces(0.0, q, zero, &force);
    m.Constraints(0.0, q, &phi);
    Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(n + rows, n + rows);
    jacobian.topLeftCorner(n, n) = force_q - curvature;
    jacobian.topRightCorner(n, rows) = -phi_q.transpose();
    jacobian.bottomLeftCorner(rows, n) = phi_q;
    Eigen::VectorXd residual(n + rows);
    residual << force - phi_q.transpose() * lambda, phi;
    const Eigen::VectorXd step = -jacobian.fullPivLu().solve(residual);
    q += step.head(n);
    lambda += step.tail(rows);
  }
  // The rod's nodes are the only bodies: node 0 at the wall, the tip last.
  BeamLoads root;
  EXPECT_TRUE(m.BeamEndLoads(0, q, zero, &root));
  const double area = p[0];
  const double fibre_per_inertia = std::sqrt(area / std::numbers::pi) / (area * area / (4 * std::numbers::pi));
  return {-root.moment_a_n_m * fibre_per_inertia, q[n - 2]};
}

TEST(StressSensitivity, StaticStressesAgreeWithDifferencesOfPolishedEquilibria) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile(kProppedCantilever);
  ASSERT_TRUE(scene.ok()) << scene.status();
  const std::vector<double> p = Values(*scene);
  const MultibodySensitivityResult result = AnalyzeMultibodySceneWithSensitivities(*scene, p, {0, 1, 2, 3, 4});
  ASSERT_TRUE(result.report.ok()) << result.report.failure.reason;
  ASSERT_EQ(result.unavailable, "");
  ASSERT_EQ(result.output_derivatives.size(), p.size());
  double worst = 0.0;
  for (size_t i = 0; i < p.size(); ++i) {
    const double h = 1e-4 * p[i];
    std::vector<double> plus = p, minus = p;
    plus[i] += h;
    minus[i] -= h;
    const Polished up = PolishedEquilibrium(*scene, plus), down = PolishedEquilibrium(*scene, minus);
    const double d_stress = (up.root_stress_pa - down.root_stress_pa) / (2 * h);
    const double d_tip = (up.tip_y_m - down.tip_y_m) / (2 * h);
    const double simulator_stress = result.output_derivatives[i][1][0][0];
    const double simulator_tip = result.output_derivatives[i][0][0][0];
    worst = std::max({worst, std::abs(simulator_stress - d_stress) / std::abs(d_stress),
                      std::abs(simulator_tip - d_tip) / std::abs(d_tip)});
    std::cout << scene->parameters[i].name << ": d root stress " << simulator_stress << " (differences " << d_stress
              << "), d tip " << simulator_tip << " (" << d_tip << ")\n";
  }
  std::cout << "worst relative difference " << worst << "\n";
  EXPECT_LT(worst, 1e-6);
}

TEST(StressSensitivity, KinematicStressesAgreeWithCentralDifferences) {
  absl::StatusOr<spec::Scene> scene = LoadText(kGuidedBeam);
  ASSERT_TRUE(scene.ok()) << scene.status();
  const spec::AnalysisReport report = AnalyzeMultibodyScene(*scene, Values(*scene));
  ASSERT_TRUE(report.ok()) << report.failure.reason;
  EXPECT_EQ(report.formulation, spec::Formulation::kKinematic);
  // At t = 1 s the tip is 1 mm across: 6 E delta r / L^2 at the root
  // (6.8 MPa; the chord's stretch of delta^2 / 2 L is below 1e-6 of it).
  const double radius = std::sqrt(1e-4 / std::numbers::pi);
  ASSERT_EQ(report.outputs[1].series.size(), 2u);
  EXPECT_NEAR(std::abs(report.outputs[1].series[0].back()) / (6 * 2e11 * 1e-3 * radius), 1.0, 1e-5);
  const double worst = WorstRelativeDifference(*scene, 1e-5);
  std::cout << "worst relative difference " << worst << "\n";
  EXPECT_LT(worst, 1e-6);
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
