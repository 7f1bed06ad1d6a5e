// Spatial scenes from their text to their outputs: loading errors that name
// the file, line, field and what was expected; Euler angles both ways; and
// the outputs of `mbopt-worker eval`'s analysis (the engine's table of model
// kinds) against closed forms: a driven crank's marker on its circle, a
// conical pendulum's marker height and its energy, a mass on a prismatic
// joint and a spring oscillating about its equilibrium.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "spec/io/study_io.h"
#include "tests/spatial/scene_text_testing.h"
#include "worker/engine/analysis.h"
#include "worker/engine/model_kinds.h"
#include "worker/spatial/euler_angles.h"
#include "worker/spatial/euler_parameters.h"

namespace mbopt::spatial {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double kPi = std::numbers::pi;

using scene_text::Series;

constexpr char kFileLabel[] = "spatial.scene.textproto";
spec::Scene Load(const std::string& text) { return scene_text::Load(text, kFileLabel); }
std::string LoadError(const std::string& text) { return scene_text::LoadError(text, kFileLabel); }

// A crank turning at a constant rate about a hinge whose axis is tilted by
// ZYX angles (30, 40, 0) deg, its tip `radius` from the axis: the tip runs
// on the circle R0 (r cos wt, r sin wt, 0), the body's ZYZ angles are
// (30 deg, 40 deg, wt).
constexpr char kDrivenCrank[] = R"pb(
  name: "driven crank"
  parameters { name: "radius" value: 120 unit: "mm" }
  parameters { name: "speed" value: 3 unit: "rad/s" }
  spatial {
    ground_markers {
      name: "hinge"
      orientation { euler_angles { sequence: EULER_ZYX angles_deg: [30, 40, 0] } }
    }
    bodies {
      name: "crank"
      mass_kg { value: 2 }
      principal_inertia { moments_kg_m2 { x { value: 0.01 } y { value: 0.02 } z { value: 0.025 } } }
      orientation { euler_angles { sequence: EULER_ZYX angles_deg: [30, 40, 0] } }
      markers { name: "hub" }
      markers { name: "tip" position_m { x { param: "radius" } } }
    }
    joints { name: "motor" kind: SPATIAL_JOINT_REVOLUTE a: "ground.hinge" b: "crank.hub" }
    drivers { joint: "motor" constant_rate { rate { param: "speed" } } }
    gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
  }
  outputs { name: "tip_x" marker_position { marker: "crank.tip" axis: AXIS_X } }
  outputs { name: "tip_y" marker_position { marker: "crank.tip" axis: AXIS_Y } }
  outputs { name: "tip_z" marker_position { marker: "crank.tip" axis: AXIS_Z } }
  outputs { name: "tip_vz" marker_velocity { marker: "crank.tip" axis: AXIS_Z } }
  outputs { name: "tip_ax" marker_acceleration { marker: "crank.tip" axis: AXIS_X } }
  outputs { name: "angle" joint_coordinate { joint: "motor" } }
  outputs { name: "rate" joint_rate { joint: "motor" } }
  outputs { name: "precession" body_orientation { body: "crank" sequence: EULER_ZYZ angle: 1 } }
  outputs { name: "nutation" body_orientation { body: "crank" sequence: EULER_ZYZ angle: 2 } }
  outputs { name: "spin" body_orientation { body: "crank" sequence: EULER_ZYZ angle: 3 } }
  time_grid { start_s: 0 end_s: 1.5 points: 31 }
  integrator { relative_tolerance: 1e-9 absolute_tolerance: 1e-9 }
)pb";

TEST(SpatialScene, DrivenCrankTipRunsOnItsCircle) {
  const spec::Scene scene = Load(kDrivenCrank);
  ASSERT_EQ(std::string(engine::ModelKindOf(scene).name), "spatial");
  const spec::AnalysisReport r = engine::Analyze(scene, scene.DefaultParameterValues());
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  // Its one degree of freedom driven: kinematics, no time integration.
  EXPECT_EQ(r.formulation, spec::Formulation::kKinematic);
  EXPECT_GT(r.counters.time_steps, 0);
  EXPECT_EQ(r.counters.rhs_evaluations, 0);
  const double radius = 0.12, w = 3.0;
  const Matrix3d tilt = RotationOfEulerAngles({2, 1, 0}, Vector3d(kPi / 6, 2 * kPi / 9, 0));
  double worst_position = 0, worst_motion = 0, worst_angle = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double a = w * r.times_s[i];
    const Vector3d tip = tilt * Vector3d(radius * std::cos(a), radius * std::sin(a), 0);
    const Vector3d velocity = tilt * Vector3d(-radius * w * std::sin(a), radius * w * std::cos(a), 0);
    const Vector3d acceleration = tilt * Vector3d(-radius * w * w * std::cos(a), -radius * w * w * std::sin(a), 0);
    worst_position = std::max({worst_position, std::abs(Series(r, "tip_x")[i] - tip.x()),
                               std::abs(Series(r, "tip_y")[i] - tip.y()), std::abs(Series(r, "tip_z")[i] - tip.z())});
    worst_motion = std::max({worst_motion, std::abs(Series(r, "tip_vz")[i] - velocity.z()),
                             std::abs(Series(r, "tip_ax")[i] - acceleration.x()),
                             std::abs(Series(r, "rate")[i] - w)});
    worst_angle = std::max({worst_angle, std::abs(std::remainder(Series(r, "angle")[i] - a, 2 * kPi)),
                            std::abs(Series(r, "precession")[i] - kPi / 6),
                            std::abs(Series(r, "nutation")[i] - 2 * kPi / 9),
                            std::abs(std::remainder(Series(r, "spin")[i] - a, 2 * kPi))});
  }
  EXPECT_LT(worst_position, 1e-8);
  EXPECT_LT(worst_motion, 1e-6);
  EXPECT_LT(worst_angle, 1e-8);
  std::cout << "driven crank: largest error of the tip " << worst_position << " m, of its velocity, acceleration and "
            << "the joint rate " << worst_motion << ", of the angles " << worst_angle << " rad; " << r.counters.time_steps
            << " steps\n";
}

// The conical pendulum of spatial_dynamics_test written as a scene, its
// start from expressions of the parameters: the bob keeps its height
// -l cos(theta), its x is -l sin(theta) cos(Omega t), and kinetic plus
// potential energy stay what they were.
constexpr char kConicalPendulum[] = R"pb(
  parameters { name: "l" value: 0.8 unit: "m" }
  parameters { name: "theta" value: 0.6 unit: "rad" }
  parameters { name: "omega" expr: "sqrt(9.81 / (l * cos(theta)))" unit: "rad/s" }
  spatial {
    ground_markers { name: "pivot" }
    bodies {
      name: "bob"
      mass_kg { value: 1.5 }
      principal_inertia { moments_kg_m2 { x { value: 0.01 } y { value: 0.01 } z { value: 0.01 } } }
      position_m { x { expr: "-l * sin(theta)" } z { expr: "-l * cos(theta)" } }
      orientation { axis_angle { axis { y { value: 1 } } angle_rad { param: "theta" } } }
      velocity_m_per_s { y { expr: "-omega * l * sin(theta)" } }
      angular_velocity_rad_per_s { z { param: "omega" } }
      markers { name: "centre" }
      markers { name: "rod_end" position_m { z { param: "l" } } }
    }
    joints { name: "pivot" kind: SPATIAL_JOINT_SPHERICAL a: "ground.pivot" b: "bob.rod_end" }
    gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
  }
  outputs { name: "x" marker_position { marker: "bob.centre" axis: AXIS_X } }
  outputs { name: "height" marker_position { marker: "bob.centre" axis: AXIS_Z } }
  outputs { name: "kinetic" kinetic_energy {} }
  outputs { name: "potential" potential_energy {} }
  time_grid { start_s: 0 end_s: 1 points: 21 }
  integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-10 }
)pb";

void CheckConicalPendulumScene(const std::string& text) {
  const spec::Scene scene = Load(text);
  const spec::AnalysisReport r = engine::Analyze(scene, scene.DefaultParameterValues());
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  const double l = 0.8, theta = 0.6, omega = std::sqrt(9.81 / (l * std::cos(theta)));
  const double energy0 = Series(r, "kinetic")[0] + Series(r, "potential")[0];
  // At rest nothing would move: the start must carry the conical motion.
  EXPECT_NEAR(Series(r, "kinetic")[0],
              0.5 * 1.5 * std::pow(omega * l * std::sin(theta), 2) + 0.5 * 0.01 * omega * omega, 1e-9);
  double worst_height = 0, worst_x = 0, worst_energy = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    worst_height = std::max(worst_height, std::abs(Series(r, "height")[i] + l * std::cos(theta)));
    worst_x = std::max(worst_x, std::abs(Series(r, "x")[i] + l * std::sin(theta) * std::cos(omega * r.times_s[i])));
    worst_energy =
        std::max(worst_energy, std::abs(Series(r, "kinetic")[i] + Series(r, "potential")[i] - energy0));
  }
  EXPECT_LT(worst_height, 1e-8);
  EXPECT_LT(worst_x, 1e-7);
  EXPECT_LT(worst_energy, 1e-7 * std::abs(energy0));
  std::cout << "conical pendulum scene: height error " << worst_height << " m, x error " << worst_x
            << " m, energy drift " << worst_energy << " J of " << energy0 << " J\n";
}

TEST(SpatialScene, ConicalPendulumKeepsItsHeightAndEnergy) { CheckConicalPendulumScene(kConicalPendulum); }

// The same scene on the explicit path (`method: EXPLICIT_RUNGE_KUTTA`),
// to the same bounds: the loader takes the method in a spatial scene and
// the analysis integrates with it.
TEST(SpatialScene, ConicalPendulumOnTheExplicitPath) {
  std::string text = kConicalPendulum;
  const std::string block = "integrator {";
  text.insert(text.find(block) + block.size(), " method: EXPLICIT_RUNGE_KUTTA");
  EXPECT_EQ(Load(text).integrator.method, spec::IntegratorMethod::kExplicitRungeKutta);
  CheckConicalPendulumScene(text);
}


// A 1 kg block on a vertical prismatic joint hanging from a spring
// (k = 100 N/m, L0 = 0.4 m) released 0.6 m below the anchor: the spring's
// length is L_eq + (0.6 - L_eq) cos(10 t), L_eq = L0 + m g / k.
constexpr char kHangingBlock[] = R"pb(
  parameters { name: "stiffness" value: 100 unit: "N/m" }
  spatial {
    ground_markers { name: "anchor" }
    bodies {
      name: "block"
      mass_kg { value: 1 }
      inertia_components { ixx_kg_m2 { value: 0.002 } iyy_kg_m2 { value: 0.002 } izz_kg_m2 { value: 0.003 } }
      position_m { z { value: -0.6 } }
      markers { name: "centre" }
    }
    joints { name: "slide" kind: SPATIAL_JOINT_PRISMATIC a: "ground.anchor" b: "block.centre" }
    springs {
      name: "spring" a: "ground.anchor" b: "block.centre"
      free_length_m { value: 0.4 } stiffness_n_per_m { param: "stiffness" }
    }
    gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
  }
  outputs { name: "slide" joint_coordinate { joint: "slide" } }
  outputs { name: "slide_rate" joint_slide_rate { joint: "slide" } }
  outputs { name: "length" spring_length { spring: "spring" } }
  outputs { name: "force" spring_force { spring: "spring" } }
  time_grid { start_s: 0.1 end_s: 2 points: 20 }
  integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-10 }
)pb";

TEST(SpatialScene, HangingBlockOscillatesAboutItsEquilibrium) {
  const spec::Scene scene = Load(kHangingBlock);
  const spec::AnalysisReport r = engine::Analyze(scene, scene.DefaultParameterValues());
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  ASSERT_EQ(r.times_s.size(), 20u);
  const double equilibrium = 0.4 + 9.81 / 100, w = 10.0;
  double worst_length = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double t = r.times_s[i];
    const double length = equilibrium + (0.6 - equilibrium) * std::cos(w * t);
    worst_length = std::max(worst_length, std::abs(Series(r, "length")[i] - length));
    EXPECT_NEAR(Series(r, "length")[i], length, 1e-8) << "t = " << t;
    EXPECT_NEAR(Series(r, "slide")[i], -length, 1e-8) << "t = " << t;
    EXPECT_NEAR(Series(r, "slide_rate")[i], (0.6 - equilibrium) * w * std::sin(w * t), 1e-7) << "t = " << t;
    EXPECT_NEAR(Series(r, "force")[i], 100 * (length - 0.4), 1e-6) << "t = " << t;
  }
  std::cout << "hanging block: largest spring length error " << worst_length << " m\n";
  // A design point's stiffness reaches the spring: twice as stiff, the
  // equilibrium rises.
  std::vector<double> stiffer = scene.DefaultParameterValues();
  stiffer[0] = 200;
  const spec::AnalysisReport s = engine::Analyze(scene, stiffer);
  ASSERT_TRUE(s.ok()) << s.failure.reason;
  const double stiff_equilibrium = 0.4 + 9.81 / 200, w2 = std::sqrt(200.0);
  EXPECT_NEAR(Series(s, "length")[5],
              stiff_equilibrium + (0.6 - stiff_equilibrium) * std::cos(w2 * s.times_s[5]), 1e-8);
}

// A door on two coaxial hinges (world z), its centre of mass level with
// them, swinging under gravity along -y: the upper hinge repeats five of
// the lower one's equations. Counted and handled, not refused: the door
// swings as on the lower hinge alone.
constexpr char kDoorOnTwoHinges[] = R"pb(
  spatial {
    ground_markers { name: "low" position_m { z { value: -0.8 } } }
    ground_markers { name: "high" position_m { z { value: 0.8 } } }
    bodies {
      name: "door"
      mass_kg { value: 12 }
      principal_inertia { moments_kg_m2 { x { value: 1.0 } y { value: 1.2 } z { value: 0.25 } } }
      position_m { x { value: 0.4 } }
      markers { name: "low" position_m { x { value: -0.4 } z { value: -0.8 } } }
      markers { name: "high" position_m { x { value: -0.4 } z { value: 0.8 } } }
    }
    joints { name: "lower" kind: SPATIAL_JOINT_REVOLUTE a: "ground.low" b: "door.low" }
    joints { name: "upper" kind: SPATIAL_JOINT_REVOLUTE a: "ground.high" b: "door.high" }
    gravity { acceleration_m_per_s2 { y { value: -9.81 } } }
  }
  outputs { name: "angle" joint_coordinate { joint: "lower" } }
  outputs { name: "kinetic" kinetic_energy {} }
  outputs { name: "potential" potential_energy {} }
  time_grid { start_s: 0 end_s: 2 points: 41 }
  integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-10 }
)pb";

TEST(SpatialScene, RedundantHingesAreHandledNotRefused) {
  const spec::Scene two = Load(kDoorOnTwoHinges);
  const spec::AnalysisReport r = engine::Analyze(two, two.DefaultParameterValues());
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  std::string one_hinge = kDoorOnTwoHinges;
  const std::string upper = R"(joints { name: "upper" kind: SPATIAL_JOINT_REVOLUTE a: "ground.high" b: "door.high" })";
  one_hinge.erase(one_hinge.find(upper), upper.size());
  const spec::Scene one = Load(one_hinge);
  const spec::AnalysisReport r1 = engine::Analyze(one, one.DefaultParameterValues());
  ASSERT_TRUE(r1.ok()) << r1.failure.reason;
  const double energy0 = Series(r, "kinetic")[0] + Series(r, "potential")[0];
  double worst_angle = 0, worst_energy = 0, swing = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    worst_angle = std::max(worst_angle, std::abs(Series(r, "angle")[i] - Series(r1, "angle")[i]));
    worst_energy = std::max(worst_energy, std::abs(Series(r, "kinetic")[i] + Series(r, "potential")[i] - energy0));
    swing = std::max(swing, std::abs(Series(r, "angle")[i]));
  }
  EXPECT_GT(swing, 1.0);              // rad: it swings through the bottom
  EXPECT_LT(worst_angle, 5e-8);       // rad
  EXPECT_LT(worst_energy, 1e-7 * 12 * 9.81 * 0.4);  // J, relative to the drop to the bottom
  std::cout << "door on two hinges (scene): angle differs from one hinge's by " << worst_angle << " rad, energy drift "
            << worst_energy << " J\n";
}

// Redundant hinges on the explicit path: the rows integrated as
// independent combinations and projected, as on IDAS.
TEST(SpatialScene, RedundantHingesOnTheExplicitPath) {
  std::string text = kDoorOnTwoHinges;
  const std::string block = "integrator {";
  ASSERT_NE(text.find(block), std::string::npos);
  text.insert(text.find(block) + block.size(), " method: EXPLICIT_RUNGE_KUTTA");
  const spec::Scene erk = Load(text);
  const spec::Scene idas = Load(kDoorOnTwoHinges);
  const spec::AnalysisReport r = engine::Analyze(erk, erk.DefaultParameterValues());
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  const spec::AnalysisReport r0 = engine::Analyze(idas, idas.DefaultParameterValues());
  ASSERT_TRUE(r0.ok()) << r0.failure.reason;
  double worst = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    worst = std::max(worst, std::abs(Series(r, "angle")[i] - Series(r0, "angle")[i]));
  }
  EXPECT_LT(worst, 5e-8);  // rad, the bound of the one-hinge comparison
  std::cout << "door on two hinges, explicit path: angle differs from IDAS's by " << worst << " rad\n";
}

// A redundant mechanism's multipliers belong to combinations of rows: its
// reactions are not unique, so asking for one fails the analysis naming it.
TEST(SpatialScene, ReactionsOfARedundantMechanismAreRefusedNamingTheOutput) {
  std::string text = kDoorOnTwoHinges;
  const std::string kinetic = R"(outputs { name: "kinetic" kinetic_energy {} })";
  text.replace(text.find(kinetic), kinetic.size(),
               R"(outputs { name: "lower_fx" joint_reaction { joint: "lower" axis: AXIS_X } })");
  const spec::Scene scene = Load(text);
  const spec::AnalysisReport r = engine::Analyze(scene, scene.DefaultParameterValues());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_NE(r.failure.reason.find("output 'lower_fx'"), std::string::npos) << r.failure.reason;
  EXPECT_NE(r.failure.reason.find("redundant constraint equation"), std::string::npos) << r.failure.reason;
}

TEST(SpatialScene, OnlyRequestedOutputsAreComputed) {
  std::string text = kHangingBlock;
  text = text.substr(0, text.find("  outputs")) + "time_grid { start_s: 0 end_s: 1 points: 3 }";
  const spec::Scene scene = Load(text);
  const spec::AnalysisReport r = engine::Analyze(scene, scene.DefaultParameterValues());
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.outputs.empty());
  EXPECT_EQ(r.counters.time_steps, 0);
}

TEST(SpatialScene, ImpossibleInertiaFailsTheAnalysisNamingTheBody) {
  std::string text = kHangingBlock;
  text.replace(text.find("izz_kg_m2 { value: 0.003 }"), 26, "izz_kg_m2 { value: 0.005 }");
  const spec::Scene scene = Load(text);
  const spec::AnalysisReport r = engine::Analyze(scene, scene.DefaultParameterValues());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_NE(r.failure.reason.find("body 'block'"), std::string::npos) << r.failure.reason;
  EXPECT_NE(r.failure.reason.find("triangle inequality"), std::string::npos) << r.failure.reason;
}

// Every loading error names the file, the line, the field's path and what
// was expected.
TEST(SpatialScene, LoadingErrorsNameFileLineFieldAndExpectation) {
  std::string text = kDrivenCrank;
  text.replace(text.find("b: \"crank.hub\""), 14, "b: \"crank.hob\"");
  std::string error = LoadError(text);
  EXPECT_NE(error.find("spatial.scene.textproto:"), std::string::npos) << error;
  EXPECT_NE(error.find("spatial.joints[0].b: \"crank\" has no marker \"hob\" (markers: hub, tip)"), std::string::npos)
      << error;
  const std::string line_of_joint = absl::StrCat(":", 1 + std::count(text.begin(), text.begin() + text.find("crank.hob"), '\n'), ":");
  EXPECT_NE(error.find(line_of_joint), std::string::npos) << error << " expected " << line_of_joint;

  text = kDrivenCrank;
  text.replace(text.find("sequence: EULER_ZYX"), 19, "");
  error = LoadError(text);
  EXPECT_NE(error.find("spatial.ground_markers[0].orientation.euler_angles.sequence: missing or unknown: expected "
                       "one of EULER_XYZ"),
            std::string::npos)
      << error;

  text = kDrivenCrank;
  text.replace(text.find("angles_deg: [30, 40, 0]"), 23, "angles_deg: [30, 40]");
  error = LoadError(text);
  EXPECT_NE(error.find("euler_angles.angles_deg: expected three angles, got 2"), std::string::npos) << error;

  text = kDrivenCrank;
  text.replace(text.find("SPATIAL_JOINT_REVOLUTE"), 22, "SPATIAL_JOINT_SPHERICAL");
  error = LoadError(text);
  EXPECT_NE(error.find("spatial.drivers[0].joint: joint \"motor\" is not revolute, prismatic or cylindrical"),
            std::string::npos)
      << error;

  text = kDrivenCrank;
  text.replace(text.find("principal_inertia"), text.find("orientation {", text.find("principal_inertia")) -
                                                    text.find("principal_inertia"), "");
  error = LoadError(text);
  EXPECT_NE(error.find("spatial.bodies[0]: missing inertia: expected `principal_inertia"), std::string::npos) << error;

  text = kDrivenCrank;
  text.replace(text.find("angle: 3"), 8, "angle: 4");
  error = LoadError(text);
  EXPECT_NE(error.find("outputs[9].body_orientation.angle: expected 1, 2 or 3"), std::string::npos) << error;

  text = kDrivenCrank;
  text.replace(text.find("axis: AXIS_Z"), 12, "");
  error = LoadError(text);
  EXPECT_NE(error.find("outputs[2].marker_position.axis: expected AXIS_X, AXIS_Y or AXIS_Z"), std::string::npos)
      << error;

  text = kDrivenCrank;
  text.replace(text.find("joint_rate { joint: \"motor\" }"), 29, "joint_slide { joint: \"motor\" }");
  error = LoadError(text);
  EXPECT_NE(error.find("outputs[6].joint_slide.joint: joint \"motor\" has no slide"), std::string::npos) << error;

  text = std::string(kDrivenCrank) + "effects { gravity { acceleration_m_per_s2 { y { value: -9.81 } } } }";
  error = LoadError(text);
  EXPECT_NE(error.find("a spatial scene takes no `effects`"), std::string::npos) << error;

  text = kDrivenCrank;
  text.replace(text.find("outputs { name: \"tip_x\""), 0,
               "outputs { name: \"pull\" joint_reaction { joint: \"mot\" axis: AXIS_X } }\n");
  error = LoadError(text);
  EXPECT_NE(error.find("outputs[0].joint_reaction.joint: unknown joint \"mot\" (joints: motor)"), std::string::npos)
      << error;
}

TEST(SpatialScene, SpatialOutputsAreRefusedInPlanarScenes) {
  const std::string error = LoadError(R"pb(
    multibody {
      bodies { name: "b" mass_kg { value: 1 } inertia_kg_m2 { value: 1 } markers { name: "m" } }
    }
    outputs { name: "o" body_orientation { body: "b" sequence: EULER_ZYX angle: 1 } }
    outputs { name: "z" marker_position { marker: "b.m" axis: AXIS_Z } }
    time_grid { end_s: 1 points: 2 }
  )pb");
  EXPECT_NE(error.find("output \"o\" needs a spatial model; this scene's model is multibody"), std::string::npos)
      << error;
  EXPECT_NE(error.find("outputs[1].marker_position.axis: expected AXIS_X or AXIS_Y"), std::string::npos) << error;
}

// Every sequence, away from and at its singular middle angle: the angles of
// a rotation give that rotation back, and angles within the stated ranges
// come back as they were.
TEST(EulerAngles, RoundTripEverySequence) {
  const std::vector<EulerSequence> sequences = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0},
                                                {0, 1, 0}, {0, 2, 0}, {1, 0, 1}, {1, 2, 1}, {2, 0, 2}, {2, 1, 2}};
  for (const EulerSequence& s : sequences) {
    const bool proper = s[0] == s[2];
    for (const Vector3d& angles :
         {Vector3d(0.3, proper ? 1.1 : -0.7, -2.5), Vector3d(-2.9, proper ? 2.8 : 1.4, 0.2),
          Vector3d(1.0, proper ? 0.0 : kPi / 2, 0.0), Vector3d(-0.4, proper ? kPi : -kPi / 2, 0.0)}) {
      const Matrix3d r = RotationOfEulerAngles(s, angles);
      const Vector3d back = EulerAnglesOf(s, r);
      EXPECT_LT((RotationOfEulerAngles(s, back) - r).cwiseAbs().maxCoeff(), 1e-12)
          << s[0] << s[1] << s[2] << " " << angles.transpose();
      const bool singular = proper ? std::abs(std::sin(angles[1])) < 1e-9 : std::abs(std::cos(angles[1])) < 1e-9;
      if (!singular) {
        EXPECT_LT((back - angles).cwiseAbs().maxCoeff(), 1e-12) << s[0] << s[1] << s[2] << " " << back.transpose();
      }
    }
  }
}

}  // namespace
}  // namespace mbopt::spatial
