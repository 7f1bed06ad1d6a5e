// examples/spatial/governor.study.textproto (and the static hung_linkage
// studies, at the end) optimized in this process (the
// service's job driver with an in-process evaluator): finite differences of
// spatial forward-dynamics analyses reach the optimum the study describes,
// the shortest arm and the spring that puts the flyweight on its radius
// limit; and two mechanisms with redundant joints (coaxial hinges) whose
// simulator sensitivities reach the optimum of finite differences: a bob
// in static equilibrium (a closed-form optimum) and a swinging door.
#include <cmath>
#include <fstream>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "spec/io/study_io.h"
#include "tests/testing/local_run/local_run.h"

namespace mbopt::local_run {
namespace {

TEST(RunStudyLocally, SpatialGovernorTakesTheShortestArmAndTheSpringOnTheLimit) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("examples/spatial/governor.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  absl::StatusOr<LocalRunResult> result = RunStudyLocally(*study);
  ASSERT_TRUE(result.ok()) << result.status();
  const RunOutcome& run = result->outcome;
  EXPECT_EQ(run.state, slp::RunState::kConverged) << slp::RunStateName(run.state) << " " << result->end_reason;
  // On the limit: the radius constraint active, within 1e-4 of it.
  EXPECT_LE(std::abs(run.max_violation), 1e-4);
  ASSERT_EQ(result->design_physical.size(), 2u);
  // The arm at its lower bound, 60 mm; the stiffness far below the start's
  // 200 N/m (a softer spring lets the flyweight out to the limit): 31.5
  // N/m when this was written, in 9 cycles and 29 analyses.
  EXPECT_NEAR(result->design_physical[1], 60.0, 1e-3);
  EXPECT_GT(result->design_physical[0], 10.0);
  EXPECT_LT(result->design_physical[0], 100.0);
  std::cout << "governor: state " << slp::RunStateName(run.state) << " k " << result->design_physical[0]
            << " N/m, arm " << result->design_physical[1] << " mm, maxg " << run.max_violation << ", cycles "
            << run.cycles << ", analyses " << run.analyses << ", wall " << result->wall_seconds << " s\n";
}

// The same study with simulator sensitivities
// (examples/spatial/governor_sensitivity.study.textproto): IDAS forward
// sensitivities of the spatial system give the optimizer the gradients
// finite differences give it, so it reaches the same optimum with one
// analysis per cycle instead of 1 + 2.
TEST(RunStudyLocally, SpatialGovernorWithSimulatorSensitivitiesReachesTheSameOptimumWithFewerAnalyses) {
  absl::StatusOr<spec::Study> differences_study = spec::io::LoadStudyFile("examples/spatial/governor.study.textproto");
  absl::StatusOr<spec::Study> simulator_study =
      spec::io::LoadStudyFile("examples/spatial/governor_sensitivity.study.textproto");
  ASSERT_TRUE(differences_study.ok()) << differences_study.status();
  ASSERT_TRUE(simulator_study.ok()) << simulator_study.status();
  ASSERT_TRUE(simulator_study->optimizer.simulator_sensitivities);
  ASSERT_FALSE(differences_study->optimizer.simulator_sensitivities);
  absl::StatusOr<LocalRunResult> differences = RunStudyLocally(*differences_study);
  absl::StatusOr<LocalRunResult> simulator = RunStudyLocally(*simulator_study);
  ASSERT_TRUE(differences.ok()) << differences.status();
  ASSERT_TRUE(simulator.ok()) << simulator.status();
  EXPECT_EQ(simulator->outcome.state, slp::RunState::kConverged)
      << slp::RunStateName(simulator->outcome.state) << " " << simulator->end_reason;
  EXPECT_EQ(simulator->analyses_failed, 0);
  ASSERT_EQ(simulator->design_physical.size(), 2u);
  ASSERT_EQ(differences->design_physical.size(), 2u);
  // The same optimum: the arm on its bound, the stiffness within 0.1 % (the
  // radius constraint is met to 1e-4 of its limit either way).
  EXPECT_NEAR(simulator->design_physical[1], differences->design_physical[1], 1e-3);
  EXPECT_NEAR(simulator->design_physical[0], differences->design_physical[0], 1e-3 * differences->design_physical[0]);
  EXPECT_LE(std::abs(simulator->outcome.max_violation), 1e-4);
  EXPECT_LT(simulator->analyses_run, differences->analyses_run);
  std::cout << "governor: " << simulator->outcome.cycles << " cycles, " << simulator->analyses_run
            << " analyses, " << simulator->wall_seconds << " s with simulator sensitivities (k "
            << simulator->design_physical[0] << " N/m, arm " << simulator->design_physical[1] << " mm); "
            << differences->outcome.cycles << " cycles, " << differences->analyses_run << " analyses, "
            << differences->wall_seconds << " s with finite differences (k " << differences->design_physical[0]
            << " N/m, arm " << differences->design_physical[1] << " mm)\n";
}

// A static spatial scene (examples/spatial/hung_linkage*.study.textproto):
// the equilibria's simulator sensitivities (the equilibrium equations
// differentiated) give the optimum finite differences of static analyses
// give, the farthest anchor and the spring that puts the bob's deflection
// on its 40 mm limit (64.34 N/m when this was written, in 11 cycles: 14
// analyses against 36).
TEST(RunStudyLocally, SpatialStaticLinkageWithSimulatorSensitivitiesReachesTheSameOptimum) {
  absl::StatusOr<spec::Study> differences_study = spec::io::LoadStudyFile("examples/spatial/hung_linkage.study.textproto");
  absl::StatusOr<spec::Study> simulator_study =
      spec::io::LoadStudyFile("examples/spatial/hung_linkage_sensitivity.study.textproto");
  ASSERT_TRUE(differences_study.ok()) << differences_study.status();
  ASSERT_TRUE(simulator_study.ok()) << simulator_study.status();
  ASSERT_TRUE(simulator_study->optimizer.simulator_sensitivities);
  absl::StatusOr<LocalRunResult> differences = RunStudyLocally(*differences_study);
  absl::StatusOr<LocalRunResult> simulator = RunStudyLocally(*simulator_study);
  ASSERT_TRUE(differences.ok()) << differences.status();
  ASSERT_TRUE(simulator.ok()) << simulator.status();
  for (const LocalRunResult* r : {&*differences, &*simulator}) {
    EXPECT_EQ(r->outcome.state, slp::RunState::kConverged) << slp::RunStateName(r->outcome.state) << " " << r->end_reason;
    EXPECT_EQ(r->analyses_failed, 0);
    EXPECT_LE(std::abs(r->outcome.max_violation), 1e-4);
    ASSERT_EQ(r->design_physical.size(), 2u);
    EXPECT_NEAR(r->design_physical[1], 600.0, 1e-3);  // the anchor at its upper bound (mm)
  }
  EXPECT_NEAR(simulator->design_physical[0], differences->design_physical[0], 1e-3 * differences->design_physical[0]);
  // One analysis per cycle: fewer than 1 + 2 per cycle.
  EXPECT_LT(simulator->analyses_run, differences->analyses_run);
  std::cout << "hung linkage: " << simulator->outcome.cycles << " cycles, " << simulator->analyses_run
            << " analyses with simulator sensitivities (k " << simulator->design_physical[0] << " N/m); "
            << differences->outcome.cycles << " cycles, " << differences->analyses_run
            << " analyses with finite differences (k " << differences->design_physical[0] << " N/m)\n";
}

// A bob on two coaxial hinges (five redundant joint rows, solved with
// independent combinations of them) swung out by a torque growing to
// 8 N m against gravity, in static equilibrium: the lightest bob that
// keeps its swing within 40 degrees. sin(theta) = tau / (m g l), so the
// optimum is m = 8 / (9.81 x 0.5 x sin 40 deg) = 2.5374 kg. The
// simulator's gradients (the combined equilibrium equations
// differentiated) reach it as finite differences do.
constexpr char kCoaxialBobScene[] = R"pb(
name: "coaxial_bob"
parameters { name: "mass" value: 5 unit: "kg" }
spatial {
  analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM
  ground_markers { name: "hinge" orientation { axis_angle { axis { x { value: 1 } } angle_deg: -90 } } }
  ground_markers {
    name: "hinge2" position_m { y { value: 0.3 } }
    orientation { axis_angle { axis { x { value: 1 } } angle_deg: -90 } }
  }
  bodies {
    name: "bob"
    mass_kg { param: "mass" }
    principal_inertia { moments_kg_m2 { x { value: 0.02 } y { value: 0.02 } z { value: 0.01 } } }
    position_m { z { value: -0.5 } }
    markers {
      name: "pivot" position_m { z { value: 0.5 } }
      orientation { axis_angle { axis { x { value: 1 } } angle_deg: -90 } }
    }
    markers {
      name: "pivot2" position_m { y { value: 0.3 } z { value: 0.5 } }
      orientation { axis_angle { axis { x { value: 1 } } angle_deg: -90 } }
    }
  }
  joints { name: "hinge" kind: SPATIAL_JOINT_REVOLUTE a: "ground.hinge" b: "bob.pivot" }
  joints { name: "hinge2" kind: SPATIAL_JOINT_REVOLUTE a: "ground.hinge2" b: "bob.pivot2" }
  torques {
    name: "swing" body: "bob" torque_n_m { y { value: 8 } }
    tabulated { times_s: [0, 1] values: [0, 1] }
  }
  gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
}
outputs { name: "angle" joint_coordinate { joint: "hinge" } }
time_grid { start_s: 0 end_s: 1 points: 5 }
)pb";

std::string CoaxialBobStudy(const char* sensitivity) {
  return absl::StrCat(R"pb(
name: "coaxial_bob"
scene_file: "coaxial_bob.scene.textproto"
variables { name: "m" parameter: "mass" scale: 1 initial: 5 lower: 2 upper: 8 }
responses { name: "m_response" expr: "mass" unit: "kg" }
objective { minimize: "m_response" unit: "kg" }
constraints { name: "swing" output: "angle" reduction: REDUCTION_MAX limit: 40 unit: "deg" }
optimizer { sensitivity: )pb", sensitivity, " }\n");
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

TEST(RunStudyLocally, RedundantHingesWithSimulatorSensitivitiesReachTheClosedFormOptimum) {
  const std::string dir = ::testing::TempDir();
  WriteText(dir + "/coaxial_bob.scene.textproto", kCoaxialBobScene);
  WriteText(dir + "/coaxial_bob.study.textproto", CoaxialBobStudy("SENSITIVITY_METHOD_FINITE_DIFFERENCE"));
  WriteText(dir + "/coaxial_bob_sensitivity.study.textproto", CoaxialBobStudy("SENSITIVITY_METHOD_SIMULATOR"));
  absl::StatusOr<spec::Study> differences_study = spec::io::LoadStudyFile(dir + "/coaxial_bob.study.textproto");
  absl::StatusOr<spec::Study> simulator_study =
      spec::io::LoadStudyFile(dir + "/coaxial_bob_sensitivity.study.textproto");
  ASSERT_TRUE(differences_study.ok()) << differences_study.status();
  ASSERT_TRUE(simulator_study.ok()) << simulator_study.status();
  ASSERT_TRUE(simulator_study->optimizer.simulator_sensitivities);
  absl::StatusOr<LocalRunResult> differences = RunStudyLocally(*differences_study);
  absl::StatusOr<LocalRunResult> simulator = RunStudyLocally(*simulator_study);
  ASSERT_TRUE(differences.ok()) << differences.status();
  ASSERT_TRUE(simulator.ok()) << simulator.status();
  const double optimum_kg = 8.0 / (9.81 * 0.5 * std::sin(40.0 * std::acos(-1.0) / 180.0));
  for (const LocalRunResult* r : {&*differences, &*simulator}) {
    EXPECT_EQ(r->outcome.state, slp::RunState::kConverged) << slp::RunStateName(r->outcome.state) << " " << r->end_reason;
    EXPECT_EQ(r->analyses_failed, 0);
    ASSERT_EQ(r->design_physical.size(), 1u);
    // The constraint met to 1e-4 of its limit moves the mass by about as
    // much relative to it.
    EXPECT_NEAR(r->design_physical[0], optimum_kg, 1e-3 * optimum_kg);
  }
  // One analysis per cycle: fewer than 1 + 1 per cycle.
  EXPECT_LT(simulator->analyses_run, differences->analyses_run);
  std::cout << "bob on coaxial hinges: " << simulator->outcome.cycles << " cycles, " << simulator->analyses_run
            << " analyses with simulator sensitivities (m " << simulator->design_physical[0] << " kg); "
            << differences->outcome.cycles << " cycles, " << differences->analyses_run
            << " analyses with finite differences (m " << differences->design_physical[0] << " kg); closed form "
            << optimum_kg << " kg\n";
}

// A door on two coaxial hinges about world z (five redundant joint rows,
// integrated as independent combinations of them), released level and
// swinging down under gravity against a spring from a ground anchor to its
// edge: the softest spring that keeps the edge within 400 mm of its start
// height. Forward dynamics with simulator sensitivities (IDAS on the
// combined rows) reaches the optimum finite differences reach.
constexpr char kCoaxialDoorScene[] = R"pb(
name: "coaxial_door"
parameters { name: "stiffness" value: 120 unit: "N/m" }
spatial {
  ground_markers { name: "low" }
  ground_markers { name: "high" position_m { z { value: 1.6 } } }
  ground_markers { name: "anchor" position_m { x { value: 0.5 } y { value: 0.6 } z { value: 0.3 } } }
  bodies {
    name: "door"
    mass_kg { value: 12 }
    principal_inertia { moments_kg_m2 { x { value: 1.0 } y { value: 1.2 } z { value: 0.25 } } }
    position_m { x { value: 0.4 } }
    markers { name: "low" position_m { x { value: -0.4 } } }
    markers { name: "high" position_m { x { value: -0.4 } z { value: 1.6 } } }
    markers { name: "edge" position_m { x { value: 0.4 } z { value: 0.3 } } }
  }
  joints { name: "lower" kind: SPATIAL_JOINT_REVOLUTE a: "ground.low" b: "door.low" }
  joints { name: "upper" kind: SPATIAL_JOINT_REVOLUTE a: "ground.high" b: "door.high" }
  springs {
    name: "pull" a: "ground.anchor" b: "door.edge"
    free_length_m { value: 0.2 } stiffness_n_per_m { param: "stiffness" } damping_n_s_per_m { value: 0.5 }
  }
  gravity { acceleration_m_per_s2 { y { value: -9.81 } } }
}
outputs { name: "edge_y" marker_position { marker: "door.edge" axis: AXIS_Y } }
time_grid { start_s: 0 end_s: 1.5 points: 31 }
integrator { relative_tolerance: 1e-8 absolute_tolerance: 1e-9 }
)pb";

std::string CoaxialDoorStudy(const char* sensitivity) {
  return absl::StrCat(R"pb(
name: "coaxial_door"
scene_file: "coaxial_door.scene.textproto"
variables { name: "k" parameter: "stiffness" scale: 100 initial: 1.2 lower: 0.5 upper: 3 }
responses { name: "k_response" expr: "stiffness" unit: "N/m" }
responses { name: "drop" expr: "-edge_y" unit: "m" }
objective { minimize: "k_response" unit: "N/m" }
constraints { name: "drop" output: "drop" reduction: REDUCTION_MAX limit: 400 unit: "mm" }
optimizer { sensitivity: )pb", sensitivity, " }\n");
}

TEST(RunStudyLocally, DoorOnCoaxialHingesWithSimulatorSensitivitiesReachesTheSameOptimum) {
  const std::string dir = ::testing::TempDir();
  WriteText(dir + "/coaxial_door.scene.textproto", kCoaxialDoorScene);
  WriteText(dir + "/coaxial_door.study.textproto", CoaxialDoorStudy("SENSITIVITY_METHOD_FINITE_DIFFERENCE"));
  WriteText(dir + "/coaxial_door_sensitivity.study.textproto", CoaxialDoorStudy("SENSITIVITY_METHOD_SIMULATOR"));
  absl::StatusOr<spec::Study> differences_study = spec::io::LoadStudyFile(dir + "/coaxial_door.study.textproto");
  absl::StatusOr<spec::Study> simulator_study =
      spec::io::LoadStudyFile(dir + "/coaxial_door_sensitivity.study.textproto");
  ASSERT_TRUE(differences_study.ok()) << differences_study.status();
  ASSERT_TRUE(simulator_study.ok()) << simulator_study.status();
  absl::StatusOr<LocalRunResult> differences = RunStudyLocally(*differences_study);
  absl::StatusOr<LocalRunResult> simulator = RunStudyLocally(*simulator_study);
  ASSERT_TRUE(differences.ok()) << differences.status();
  ASSERT_TRUE(simulator.ok()) << simulator.status();
  for (const LocalRunResult* r : {&*differences, &*simulator}) {
    EXPECT_EQ(r->outcome.state, slp::RunState::kConverged) << slp::RunStateName(r->outcome.state) << " " << r->end_reason;
    EXPECT_EQ(r->analyses_failed, 0);
    EXPECT_LE(std::abs(r->outcome.max_violation), 1e-4);
    ASSERT_EQ(r->design_physical.size(), 1u);
  }
  EXPECT_NEAR(simulator->design_physical[0], differences->design_physical[0], 1e-3 * differences->design_physical[0]);
  EXPECT_LT(simulator->analyses_run, differences->analyses_run);
  std::cout << "door on coaxial hinges: " << simulator->outcome.cycles << " cycles, " << simulator->analyses_run
            << " analyses with simulator sensitivities (k " << simulator->design_physical[0] << " N/m); "
            << differences->outcome.cycles << " cycles, " << differences->analyses_run
            << " analyses with finite differences (k " << differences->design_physical[0] << " N/m)\n";
}

}  // namespace
}  // namespace mbopt::local_run
