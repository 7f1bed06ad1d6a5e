// Simulator sensitivities of spatial static equilibria (the implicit
// function theorem on the equilibrium equations, multibody::
// StaticStateSensitivities, on the spatial system's exact state Jacobian)
// against central differences of whole static analyses: a two-body
// linkage (an arm on a tilted hinge, a bob hung from it on a spherical
// joint) held by a linear and a tabulated spring, pushed by a follower
// force and twisted by a torque under gravity, with respect to a mass, a
// stiffness, a marker coordinate and a load. Outputs: marker positions, the
// hinge's angle, joint reactions, a spring's force and length. Also: the
// Newton matrix is analytic now (fewer residual evaluations than the
// difference-quotient matrices). The same linkage with a bushing turned by
// tens of degrees, and with a rotational spring wound past a turn on its
// hinge: their element Jacobians are analytic too, so they have
// sensitivities and analytic Newton matrices.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "tests/spatial/scene_text_testing.h"
#include "worker/spatial/euler_angles.h"
#include "worker/spatial/spatial_scene_analysis.h"

namespace mbopt::spatial {
namespace {

// Relative step of the whole analyses' central differences: the equilibria
// are converged far below 1e-10 in their residuals (Newton's last step is
// quadratic), so the differences' noise stays near 1e-10 / 1e-4 = 1e-6 at
// worst and their truncation near 1e-8.
constexpr double kRelativeStep = 1e-4;

constexpr char kLinkage[] = R"pb(
  parameters { name: "bob_mass" value: 1.5 unit: "kg" }
  parameters { name: "stiffness" value: 300 unit: "N/m" }
  parameters { name: "anchor_y" value: 400 unit: "mm" }
  parameters { name: "push" value: 4 unit: "N" }
  spatial {
    analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM
    ground_markers {
      name: "hinge"
      orientation { euler_angles { sequence: EULER_ZYX angles_deg: [15, 0, 80] } }
    }
    ground_markers { name: "anchor" position_m { x { value: 0.1 } y { param: "anchor_y" } z { value: -0.5 } } }
    ground_markers { name: "post" position_m { x { value: -0.4 } y { value: -0.1 } z { value: -0.6 } } }
    bodies {
      name: "arm"
      mass_kg { value: 1 }
      principal_inertia { moments_kg_m2 { x { value: 0.01 } y { value: 0.01 } z { value: 0.001 } } }
      position_m { z { value: -0.15 } }
      markers {
        name: "top" position_m { z { value: 0.15 } }
        orientation { euler_angles { sequence: EULER_ZYX angles_deg: [15, 0, 80] } }
      }
      markers { name: "tip" position_m { z { value: -0.15 } } }
    }
    bodies {
      name: "bob"
      mass_kg { param: "bob_mass" }
      principal_inertia { moments_kg_m2 { x { value: 0.02 } y { value: 0.03 } z { value: 0.01 } } }
      position_m { z { value: -0.5 } }
      markers { name: "socket" position_m { z { value: 0.2 } } }
      markers { name: "left" position_m { x { value: 0.05 } y { value: 0.08 } z { value: -0.1 } } }
      markers { name: "right" position_m { x { value: -0.06 } y { value: -0.05 } z { value: -0.1 } } }
    }
    joints { name: "hinge" kind: SPATIAL_JOINT_REVOLUTE a: "ground.hinge" b: "arm.top" }
    joints { name: "socket" kind: SPATIAL_JOINT_SPHERICAL a: "arm.tip" b: "bob.socket" }
    springs {
      name: "pull" a: "ground.anchor" b: "bob.left"
      free_length_m { value: 0.2 } stiffness_n_per_m { param: "stiffness" } damping_n_s_per_m { value: 2 }
    }
    springs {
      name: "strap" a: "ground.post" b: "bob.right"
      free_length_m { value: 0.25 }
      deflection_curve { x: [-0.5, 0.05, 1] force_n: [-50, 10, 400] }
    }
    point_forces {
      name: "push" at: "bob.left" force_n { x { param: "push" } z { value: 1 } } axes: SPATIAL_LOAD_BODY_AXES
      tabulated { times_s: [0, 1] values: [0.5, 1.5] }
    }
    torques { name: "twist" body: "arm" torque_n_m { x { value: 0.3 } z { value: -0.2 } } }
    gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
  }
  outputs { name: "left_x" marker_position { marker: "bob.left" axis: AXIS_X } }
  outputs { name: "left_y" marker_position { marker: "bob.left" axis: AXIS_Y } }
  outputs { name: "right_z" marker_position { marker: "bob.right" axis: AXIS_Z } }
  outputs { name: "angle" joint_coordinate { joint: "hinge" } }
  outputs { name: "hinge_fx" joint_reaction { joint: "hinge" axis: AXIS_X } }
  outputs { name: "socket_fz" joint_reaction { joint: "socket" axis: AXIS_Z } }
  outputs { name: "pull_force" spring_force { spring: "pull" } }
  outputs { name: "strap_length" spring_length { spring: "strap" } }
  time_grid { start_s: 0 end_s: 1 points: 3 }
)pb";

spec::Scene Linkage() { return scene_text::Load(kLinkage, "linkage.scene.textproto"); }

// The largest |simulator - central difference| over outputs and instants,
// each output relative to its largest |central difference| over the
// instants, for each parameter.
double WorstDisagreement(const spec::Scene& scene) {
  const std::vector<double> p = scene.DefaultParameterValues();
  std::vector<int> indices;
  for (size_t k = 0; k < p.size(); ++k) indices.push_back(static_cast<int>(k));
  const SpatialSensitivityResult result = AnalyzeSpatialSceneWithSensitivities(scene, p, indices);
  EXPECT_TRUE(result.report.ok()) << result.report.failure.reason;
  EXPECT_EQ(result.unavailable, "");
  EXPECT_EQ(result.report.formulation, spec::Formulation::kStatic);
  if (!result.report.ok() || result.output_derivatives.size() != indices.size()) return INFINITY;
  double worst = 0.0;
  for (size_t i = 0; i < indices.size(); ++i) {
    const double h = kRelativeStep * std::abs(p[i]);
    std::vector<double> plus = p, minus = p;
    plus[i] += h;
    minus[i] -= h;
    const spec::AnalysisReport up = AnalyzeSpatialScene(scene, plus), down = AnalyzeSpatialScene(scene, minus);
    EXPECT_TRUE(up.ok() && down.ok()) << up.failure.reason << down.failure.reason;
    if (!up.ok() || !down.ok()) return INFINITY;
    for (size_t o = 0; o < scene.outputs.size(); ++o) {
      const std::string& name = scene.outputs[o].name;
      const std::vector<double>& d = result.output_derivatives[i][o];
      const std::vector<double>&u = scene_text::Series(up, name), &w = scene_text::Series(down, name);
      EXPECT_EQ(d.size(), u.size()) << name;
      double scale = 0.0, difference = 0.0;
      for (size_t t = 0; t < d.size() && t < u.size(); ++t) {
        const double fd = (u[t] - w[t]) / (2 * h);
        scale = std::max(scale, std::abs(fd));
        difference = std::max(difference, std::abs(d[t] - fd));
      }
      // Every output depends on every parameter here.
      EXPECT_GT(scale, 1e-6) << scene.parameters[i].name << " -> " << name;
      worst = std::max(worst, difference / scale);
      std::cout << scene.parameters[i].name << " -> " << name << ": max |d| " << scale << ", difference "
                << difference << " (" << difference / scale << " relative)\n";
    }
  }
  return worst;
}

// Measured: 4.8e-8 at worst relative to each output's largest derivative
// (the hinge's reaction on the anchor's coordinate), most below 1e-8.
constexpr double kAgreement = 1e-6;

TEST(SpatialStaticSensitivity, LinkageDerivativesAgreeWithCentralDifferences) {
  const double worst = WorstDisagreement(Linkage());
  EXPECT_LT(worst, kAgreement);
  std::cout << "linkage statics: worst " << worst << "\n";
}

// The analytic Newton matrix costs a residual or so per Newton iteration
// (and the line search's); difference quotients one more per unknown of
// the 14 coordinates and 12 multipliers. Measured: 167 iterations and 549
// residuals; with difference quotients the same iterations and 4669.
// The scene's static analysis, expecting a few residuals per Newton
// iteration (an analytic Newton matrix).
spec::AnalysisReport ExpectAnalyticNewtonMatrix(const spec::Scene& scene, const char* label) {
  const spec::AnalysisReport r = AnalyzeSpatialScene(scene, scene.DefaultParameterValues());
  EXPECT_TRUE(r.ok()) << r.failure.reason;
  std::cout << label << " statics: " << r.counters.newton_iterations << " Newton iterations, "
            << r.counters.rhs_evaluations << " residual evaluations\n";
  EXPECT_GT(r.counters.newton_iterations, 0);
  EXPECT_LT(r.counters.rhs_evaluations, 4 * r.counters.newton_iterations);
  return r;
}

TEST(SpatialStaticSensitivity, NewtonMatrixIsAnalytic) { ExpectAnalyticNewtonMatrix(Linkage(), "linkage"); }

// The linkage with `element` added before gravity and `outputs` after the
// others; `marker` added to the bob.
spec::Scene LinkageWith(const std::string& marker, const std::string& element, const std::string& outputs,
                        const char* file) {
  std::string text = kLinkage;
  const std::string bob_marker = "      markers { name: \"right\"", gravity = "    gravity {", grid = "  time_grid {";
  text.insert(text.find(bob_marker), marker);
  text.insert(text.find(gravity), element);
  text.insert(text.find(grid), outputs);
  return scene_text::Load(text, file);
}

// The bob held also by a bushing from the ground's post to a frame on the
// bob turned by tens of degrees about every axis, stiffnesses and dampings
// different on every axis. `outputs` adds outputs.
spec::Scene BushingLinkage(const std::string& outputs = "") {
  return LinkageWith(
      "      markers {\n        name: \"mount\" position_m { x { value: -0.06 } z { value: -0.1 } }\n"
      "        orientation { euler_angles { sequence: EULER_ZYX angles_deg: [40, -30, 50] } }\n      }\n",
      "    bushings {\n      name: \"mount\" a: \"ground.post\" b: \"bob.mount\"\n"
      "      stiffness_n_per_m { x { value: 50 } y { value: 80 } z { value: 30 } }\n"
      "      damping_n_s_per_m { x { value: 1 } y { value: 2 } z { value: 3 } }\n"
      "      rotational_stiffness_n_m_per_rad { x { value: 0.4 } y { value: 0.9 } z { value: 0.6 } }\n"
      "      rotational_damping_n_m_s_per_rad { x { value: 0.1 } y { value: 0.2 } z { value: 0.3 } }\n    }\n",
      "  outputs { name: \"mount_fy\" bushing_force { bushing: \"mount\" axis: AXIS_Y } }\n"
      "  outputs { name: \"mount_mz\" bushing_force { bushing: \"mount\" axis: AXIS_Z moment: true } }\n" +
          outputs,
      "bushing_linkage.scene.textproto");
}

// The hinge held also by a damped rotational spring wound past a turn
// (free angle 8 rad).
spec::Scene RotationalSpringLinkage() {
  return LinkageWith("",
                     "    rotational_springs {\n      name: \"torsion\" joint: \"hinge\"\n"
                     "      stiffness_n_m_per_rad { value: 0.15 } damping_n_m_s_per_rad { value: 0.5 }\n"
                     "      free_angle_rad { value: 8 }\n    }\n",
                     "  outputs { name: \"torsion_torque\" rotational_spring_torque { spring: \"torsion\" } }\n",
                     "torsion_linkage.scene.textproto");
}

// Before, both said their sensitivities were unavailable (their element
// Jacobians were difference quotients). Measured: 1.0e-7 with the bushing
// and 2.1e-8 with the rotational spring at worst (both the hinge's reaction
// on the anchor's coordinate).
TEST(SpatialStaticSensitivity, BushingDerivativesAgreeWithCentralDifferences) {
  const double worst = WorstDisagreement(BushingLinkage());
  EXPECT_LT(worst, kAgreement);
  std::cout << "bushing statics: worst " << worst << "\n";
}

TEST(SpatialStaticSensitivity, RotationalSpringDerivativesAgreeWithCentralDifferences) {
  const double worst = WorstDisagreement(RotationalSpringLinkage());
  EXPECT_LT(worst, kAgreement);
  std::cout << "rotational spring statics: worst " << worst << "\n";
}

// KINSOL's Newton matrix is analytic with a bushing or a rotational spring
// too. Measured: 118 iterations and 371 residuals with the bushing, 193
// and 729 with the rotational spring; with their Jacobians differenced the
// same iterations and 3315 and 5473 residuals. The bushing's angles at the
// equilibria: (76-78, 20-23, 34-35) deg.
TEST(SpatialStaticSensitivity, BushingNewtonMatrixIsAnalytic) {
  std::string orientation;
  for (const char* k : {"1", "2", "3"}) {
    orientation += std::string("  outputs { name: \"bob_") + k +
                   "\" body_orientation { body: \"bob\" sequence: EULER_XYZ angle: " + k + " } }\n";
  }
  const spec::AnalysisReport r = ExpectAnalyticNewtonMatrix(BushingLinkage(orientation), "bushing");
  ASSERT_TRUE(r.ok());
  // The bushing's x-y-z angles, R = A_bob R_mount (the post's axes are
  // the world's), at every instant: large rotations.
  const double to_rad = std::numbers::pi / 180.0;
  const Eigen::Matrix3d mount = RotationOfEulerAngles({2, 1, 0}, Eigen::Vector3d(40, -30, 50) * to_rad);
  for (size_t t = 0; t < r.times_s.size(); ++t) {
    const Eigen::Vector3d bob(scene_text::Series(r, "bob_1")[t], scene_text::Series(r, "bob_2")[t],
                              scene_text::Series(r, "bob_3")[t]);
    const Eigen::Vector3d angles_deg =
        EulerAnglesOf({0, 1, 2}, RotationOfEulerAngles({0, 1, 2}, bob) * mount) / to_rad;
    std::cout << "bushing angles at t = " << r.times_s[t] << " s: " << angles_deg.transpose() << " deg\n";
    EXPECT_GT(angles_deg.cwiseAbs().maxCoeff(), 30.0);
  }
}

TEST(SpatialStaticSensitivity, RotationalSpringNewtonMatrixIsAnalytic) {
  ExpectAnalyticNewtonMatrix(RotationalSpringLinkage(), "rotational spring");
}

}  // namespace
}  // namespace mbopt::spatial
