// Simulator sensitivities of spatial analyses against central differences
// of whole analyses: IDAS forward sensitivities of the flyball governor
// (examples/spatial) and of a spatial pendulum on a tilted hinge, and the
// differentiated constraint equations of the same pendulum when driven,
// with respect to a mass, a spring's stiffness and a marker's coordinate
// (which moves the assembled start). Outputs: a marker's position at every
// instant, its peak, an energy, an Euler angle of a body (through the Euler
// parameters' sensitivities), a joint angle and a joint reaction.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "spec/io/study_io.h"
#include "tests/spatial/scene_text_testing.h"
#include "tests/spatial/sensitivity_comparison.h"
#include "worker/spatial/spatial_scene_analysis.h"

namespace mbopt::spatial {
namespace {

// The whole analyses are integrated at rtol 1e-10 (the pendulum at 1e-11),
// so that their central differences (sensitivity_comparison.h) can judge
// the sensitivities.
constexpr double kRelativeTolerance = 1e-10;
constexpr double kAbsoluteTolerance = 1e-11;

using sensitivity_testing::Agreement;
using sensitivity_testing::Compare;
using sensitivity_testing::Values;

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void Replace(const std::string& from, const std::string& to, std::string* text) {
  const size_t at = text->find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text->replace(at, from.size(), to);
}

// The governor of examples/spatial with the flyweight's mass made a
// parameter, over its first 1.5 s (the spin-up swing and its peak),
// integrated tightly.
spec::Scene Governor() {
  std::string text = ReadFile("examples/spatial/governor.scene.textproto");
  Replace("mass_kg { value: 0.5 }", "mass_kg { param: \"ball_mass\" }", &text);
  Replace("spatial {", "parameters { name: \"ball_mass\" value: 0.5 unit: \"kg\" }\nspatial {", &text);
  Replace("time_grid { start_s: 0 end_s: 3 points: 61 }", "time_grid { start_s: 0 end_s: 1.5 points: 31 }", &text);
  Replace("integrator { relative_tolerance: 1e-7 absolute_tolerance: 1e-8 }",
          absl::StrCat("integrator { relative_tolerance: ", kRelativeTolerance,
                       " absolute_tolerance: ", kAbsoluteTolerance, " }"),
          &text);
  return scene_text::Load(text, "governor.scene.textproto");
}

// A rod on a hinge whose axis is tilted out of the horizontal (ZYX 20, 0,
// 80 deg), the hinge's ground marker 20 mm off the rod's initial pivot (the
// assembly moves the rod there, so the start depends on that coordinate),
// pulled sideways by a spring from a ground anchor to its tip and swinging
// under gravity. Integrated at rtol 1e-11: with the residual differenced
// along the sensitivities (before the exact state Jacobian) their
// corrector failed there at t = 0.35 s.
constexpr char kPendulum[] = R"pb(
  parameters { name: "mass" value: 2 unit: "kg" }
  parameters { name: "stiffness" value: 150 unit: "N/m" }
  parameters { name: "hinge_x" value: 20 unit: "mm" }
  spatial {
    ground_markers {
      name: "hinge" position_m { x { param: "hinge_x" } }
      orientation { euler_angles { sequence: EULER_ZYX angles_deg: [20, 0, 80] } }
    }
    ground_markers { name: "anchor" position_m { x { value: 0.3 } y { value: 0.1 } z { value: -0.5 } } }
    bodies {
      name: "rod"
      mass_kg { param: "mass" }
      principal_inertia { moments_kg_m2 { x { value: 0.03 } y { value: 0.03 } z { value: 0.002 } } }
      position_m { z { value: -0.4 } }
      markers {
        name: "hub" position_m { z { value: 0.4 } }
        orientation { euler_angles { sequence: EULER_ZYX angles_deg: [20, 0, 80] } }
      }
      markers { name: "tip" position_m { z { value: -0.4 } } }
    }
    joints { name: "hinge" kind: SPATIAL_JOINT_REVOLUTE a: "ground.hinge" b: "rod.hub" }
    springs {
      name: "pull" a: "ground.anchor" b: "rod.tip"
      free_length_m { value: 0.1 } stiffness_n_per_m { param: "stiffness" } damping_n_s_per_m { value: 0.5 }
    }
    gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
  }
  outputs { name: "tip_x" marker_position { marker: "rod.tip" axis: AXIS_X } }
  outputs { name: "tip_z" marker_position { marker: "rod.tip" axis: AXIS_Z } }
  outputs { name: "angle" joint_coordinate { joint: "hinge" } }
  outputs { name: "kinetic" kinetic_energy {} }
  outputs { name: "yaw" body_orientation { body: "rod" sequence: EULER_ZYX angle: 1 } }
  outputs { name: "reaction_z" joint_reaction { joint: "hinge" axis: AXIS_Z } }
  time_grid { start_s: 0 end_s: 1.5 points: 31 }
  integrator { relative_tolerance: 1e-11 absolute_tolerance: 1e-12 }
)pb";

// What the comparisons hold to, relative to each output's largest
// derivative, with the exact state Jacobian (measured with the settings
// above: the governor 2.5e-5 over the instants and 1.7e-5 at the peaks,
// 5.0e-5 and 2.4e-5 with the residual differenced along the
// sensitivities; the pendulum 1.2e-5 and 1.8e-6, its hinge reaction, from
// multipliers of interpolated accelerations, 4.0e-5 and 1.1e-6; the driven
// pendulum 6.7e-9). Not the 1e-6 the differences could judge: the errors
// follow the integration tolerance (the pendulum at rtol 1e-10: 8.1e-5).
constexpr double kGovernorSeriesAgreement = 4e-5;
constexpr double kGovernorPeakAgreement = 3e-5;
constexpr double kSeriesAgreement = 3e-5;
constexpr double kReactionSeriesAgreement = 1e-4;
constexpr double kPeakAgreement = 5e-6;
constexpr double kDrivenAgreement = 1e-7;
// The pendulum on a bushing and a rotational spring (below): measured
// 5.1e-6 at the peaks (the kinetic energy on the hinge's coordinate), its
// hinge reaction 1.1e-4 over the instants and 8.7e-5 at the peaks (from
// multipliers of interpolated accelerations, as the pendulum's).
constexpr double kBushedPeakAgreement = 1e-5;
constexpr double kBushedReactionAgreement = 2e-4;

TEST(SpatialSensitivity, GovernorDerivativesAgreeWithCentralDifferences) {
  const spec::Scene scene = Governor();
  const Agreement a = Compare(scene, {"ball_mass", "stiffness", "arm"},
                              {"ball_x", "ball_z", "spring_force", "tilt", "kinetic_energy"});
  EXPECT_LT(a.worst_series, kGovernorSeriesAgreement);
  EXPECT_LT(a.worst_peak, kGovernorPeakAgreement);
  std::cout << "governor: worst " << a.worst_series << " over the instants, " << a.worst_peak << " at the peaks\n";
}

TEST(SpatialSensitivity, PendulumDerivativesAgreeWithCentralDifferences) {
  const spec::Scene scene = scene_text::Load(kPendulum, "pendulum.scene.textproto");
  Agreement reaction;
  const Agreement a = Compare(scene, {"mass", "stiffness", "hinge_x"},
                              {"tip_x", "tip_z", "angle", "kinetic", "yaw", "reaction_z"}, {"reaction_z"}, &reaction);
  EXPECT_LT(a.worst_series, kSeriesAgreement);
  EXPECT_LT(a.worst_peak, kPeakAgreement);
  EXPECT_LT(reaction.worst_series, kReactionSeriesAgreement);
  EXPECT_LT(reaction.worst_peak, kPeakAgreement);
  std::cout << "pendulum: worst " << a.worst_series << " over the instants, " << a.worst_peak
            << " at the peaks; its hinge reaction " << reaction.worst_series << " and " << reaction.worst_peak << "\n";
}

// The pendulum also held by a bushing from a ground frame turned by tens
// of degrees to its tip (stiffnesses and dampings different on every axis)
// and by a damped rotational spring wound 7 rad on its hinge: F_y is the
// exact state Jacobian with them too. Before their Jacobians were
// analytic, F_y s was differenced along s and the sensitivities' corrector
// failed at t = 0.56 s. Measured: 2.3e-5 over the instants, 5.1e-6 at the
// peaks; the hinge reaction 1.1e-4 and 8.7e-5 (tip_x and the reaction on
// the hinge's coordinate), as the pendulum alone.
TEST(SpatialSensitivity, PendulumOnABushingAndARotationalSpringAgreesWithCentralDifferences) {
  std::string text = kPendulum;
  Replace("    gravity {",
          "    ground_markers {\n      name: \"mount\" position_m { x { value: -0.2 } y { value: 0.3 } z { value: -0.7 } }\n"
          "      orientation { euler_angles { sequence: EULER_ZYX angles_deg: [50, -40, 30] } }\n    }\n"
          "    bushings {\n      name: \"mount\" a: \"ground.mount\" b: \"rod.tip\"\n"
          "      stiffness_n_per_m { x { value: 30 } y { value: 50 } z { value: 20 } }\n"
          "      damping_n_s_per_m { x { value: 0.2 } y { value: 0.3 } z { value: 0.1 } }\n"
          "      rotational_stiffness_n_m_per_rad { x { value: 0.5 } y { value: 0.8 } z { value: 0.3 } }\n"
          "      rotational_damping_n_m_s_per_rad { x { value: 0.01 } y { value: 0.02 } z { value: 0.03 } }\n    }\n"
          "    rotational_springs {\n      name: \"torsion\" joint: \"hinge\"\n"
          "      stiffness_n_m_per_rad { value: 0.7 } damping_n_m_s_per_rad { value: 0.05 } free_angle_rad { value: 7 }\n"
          "    }\n    gravity {",
          &text);
  Replace("  time_grid {",
          "  outputs { name: \"mount_my\" bushing_force { bushing: \"mount\" axis: AXIS_Y moment: true } }\n"
          "  outputs { name: \"torsion\" rotational_spring_torque { spring: \"torsion\" } }\n  time_grid {",
          &text);
  const spec::Scene scene = scene_text::Load(text, "bushed_pendulum.scene.textproto");
  Agreement reaction;
  const Agreement a =
      Compare(scene, {"mass", "stiffness", "hinge_x"},
              {"tip_x", "tip_z", "angle", "kinetic", "yaw", "mount_my", "torsion", "reaction_z"}, {"reaction_z"},
              &reaction);
  EXPECT_LT(a.worst_series, kSeriesAgreement);
  EXPECT_LT(a.worst_peak, kBushedPeakAgreement);
  EXPECT_LT(reaction.worst_series, kBushedReactionAgreement);
  EXPECT_LT(reaction.worst_peak, kBushedReactionAgreement);
  std::cout << "pendulum on a bushing and a rotational spring: worst " << a.worst_series << " over the instants, "
            << a.worst_peak << " at the peaks; its hinge reaction " << reaction.worst_series << " and "
            << reaction.worst_peak << "\n";
}

// The same pendulum with its hinge driven (no degree of freedom left): the
// derivatives come from the differentiated constraint equations, the
// reaction's from inverse dynamics of the varied models.
TEST(SpatialSensitivity, DrivenPendulumDerivativesAgreeWithCentralDifferences) {
  std::string text = kPendulum;
  Replace("    gravity {", "    drivers { joint: \"hinge\" constant_rate { rate { value: 2 } } }\n    gravity {", &text);
  const spec::Scene scene = scene_text::Load(text, "driven_pendulum.scene.textproto");
  const spec::AnalysisReport plain = AnalyzeSpatialScene(scene, Values(scene));
  ASSERT_TRUE(plain.ok()) << plain.failure.reason;
  EXPECT_EQ(plain.formulation, spec::Formulation::kKinematic);
  const Agreement a =
      Compare(scene, {"mass", "stiffness", "hinge_x"}, {"tip_x", "tip_z", "kinetic", "yaw", "reaction_z"});
  EXPECT_LT(a.worst_series, kDrivenAgreement);
  EXPECT_LT(a.worst_peak, kDrivenAgreement);
  std::cout << "driven pendulum: worst " << a.worst_series << " over the instants\n";
}

}  // namespace
}  // namespace mbopt::spatial
