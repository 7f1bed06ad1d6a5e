// Simulator sensitivities of spatial mechanisms with redundant joints
// (redundant_constraints.h: the rows combined independently), in the
// three analyses that integrate or solve with the combinations:
// - forward dynamics: a door on two coaxial hinges, swinging under gravity
//   and pulled by a spring, against central differences of whole analyses
//   and against the same door on one hinge (no redundant row, the plain
//   sensitivity path); Bricard's linkage over 2.5 s, across a restart with
//   new combinations, against central differences;
// - driven kinematics: the same door driven at its hinge;
// - static equilibrium: a bob on two coaxial hinges swung out by a torque
//   against gravity, against central differences and the closed form.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/spatial/mechanism_model.h"
#include "tests/spatial/scene_text_testing.h"
#include "tests/spatial/sensitivity_comparison.h"
#include "tests/spatial/spatial_mechanisms.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/spatial/redundant_constraints.h"
#include "worker/spatial/spatial_assembly.h"
#include "worker/spatial/spatial_scene_analysis.h"
#include "worker/spatial/spatial_system.h"

namespace mbopt::spatial {
namespace {

using Eigen::VectorXd;
using sensitivity_testing::Agreement;
using sensitivity_testing::Compare;
using sensitivity_testing::IndexOf;
using sensitivity_testing::Values;

// A door on hinges about world z: the lower at the origin, the upper (when
// there) `span` above it; gravity across the axis swings it from level,
// and a spring from a ground anchor pulls its outer edge. Integrated at
// rtol 1e-11 so that central differences can judge the sensitivities.
// The span moves the upper hinge only, along the axis: nothing depends on
// it, and its sensitivities, of round-off size, are checked where no
// integrator error test has to follow them (driven and static, below).
std::string Door(bool second_hinge, bool driven) {
  std::string text = R"pb(
  parameters { name: "mass" value: 12 unit: "kg" }
  parameters { name: "span" value: 1600 unit: "mm" }
  parameters { name: "stiffness" value: 40 unit: "N/m" }
  spatial {
    ground_markers { name: "low" }
    ground_markers { name: "high" position_m { z { param: "span" } } }
    ground_markers { name: "anchor" position_m { x { value: 0.5 } y { value: 0.6 } z { value: 0.3 } } }
    bodies {
      name: "door"
      mass_kg { param: "mass" }
      principal_inertia { moments_kg_m2 { x { value: 1.0 } y { value: 1.2 } z { value: 0.25 } } }
      position_m { x { value: 0.4 } }
      markers { name: "low" position_m { x { value: -0.4 } } }
      markers { name: "high" position_m { x { value: -0.4 } z { param: "span" } } }
      markers { name: "edge" position_m { x { value: 0.4 } z { value: 0.3 } } }
    }
    joints { name: "lower" kind: SPATIAL_JOINT_REVOLUTE a: "ground.low" b: "door.low" }
    springs {
      name: "pull" a: "ground.anchor" b: "door.edge"
      free_length_m { value: 0.2 } stiffness_n_per_m { param: "stiffness" } damping_n_s_per_m { value: 0.5 }
    }
    gravity { acceleration_m_per_s2 { y { value: -9.81 } } }
)pb";
  if (second_hinge) text += R"pb(joints { name: "upper" kind: SPATIAL_JOINT_REVOLUTE a: "ground.high" b: "door.high" })pb";
  if (driven) text += R"pb(drivers { joint: "lower" constant_rate { rate { value: 2 } } })pb";
  text += R"pb(
  }
  outputs { name: "angle" joint_coordinate { joint: "lower" } }
  outputs { name: "edge_x" marker_position { marker: "door.edge" axis: AXIS_X } }
  outputs { name: "edge_y" marker_position { marker: "door.edge" axis: AXIS_Y } }
  outputs { name: "force" spring_force { spring: "pull" } }
  outputs { name: "kinetic" kinetic_energy {} }
  outputs { name: "potential" potential_energy {} }
  time_grid { start_s: 0 end_s: 1.5 points: 31 }
  integrator { relative_tolerance: 1e-11 absolute_tolerance: 1e-12 }
)pb";
  return text;
}

const std::vector<std::string> kDoorOutputs = {"angle", "edge_x", "edge_y", "force", "kinetic", "potential"};

// What the comparisons hold to, relative to each output's largest
// derivative. Measured: the door 4.9e-6 over the instants and 2.1e-7 at
// the peaks (on one hinge, without combinations, 6.0e-6 and 1.9e-6);
// Bricard's linkage 6.5e-7 in its coordinates and 1.0e-6 in its
// velocities; the driven door 1.7e-11; the bob 6.9e-8 against central
// differences (their own noise) and 1.5e-11 against the closed form; two
// hinges against one 6.6e-10. The dynamic ones follow the integration
// tolerance (rtol 1e-11), the others are a linear solve per instant.
constexpr double kDynamicAgreement = 1e-5;
constexpr double kDrivenAgreement = 1e-7;
constexpr double kStaticAgreement = 1e-6;
constexpr double kClosedFormAgreement = 1e-9;
// Two hinges against one: the same motion by different equations, each
// integrated at rtol 1e-11.
constexpr double kOneHingeAgreement = 1e-7;

// The one-hinge door, through the plain sensitivity path, is the
// baseline: the combinations must not cost agreement.
TEST(RedundantSensitivity, DoorOnTwoHingesAgreesWithCentralDifferences) {
  const spec::Scene two = scene_text::Load(Door(true, false), "door2.scene.textproto");
  const spec::Scene one = scene_text::Load(Door(false, false), "door1.scene.textproto");
  const Agreement a2 = Compare(two, {"mass", "stiffness"}, kDoorOutputs);
  const Agreement a1 = Compare(one, {"mass", "stiffness"}, kDoorOutputs);
  EXPECT_LT(a2.worst_series, kDynamicAgreement);
  EXPECT_LT(a2.worst_peak, kDynamicAgreement);
  std::cout << "door on two hinges: worst " << a2.worst_series << " over the instants, " << a2.worst_peak
            << " at the peaks; on one hinge " << a1.worst_series << " and " << a1.worst_peak << "\n";
}

// The second hinge adds only rows the first implies: the door's motion,
// and so its derivatives, are the one-hinge door's, whose sensitivities
// come from the plain path (no combination).
TEST(RedundantSensitivity, DoorOnTwoHingesHasTheDerivativesOfTheDoorOnOne) {
  const spec::Scene two = scene_text::Load(Door(true, false), "door2.scene.textproto");
  const spec::Scene one = scene_text::Load(Door(false, false), "door1.scene.textproto");
  const std::vector<int> parameters = {IndexOf(two, "mass"), IndexOf(two, "stiffness")};
  const SpatialSensitivityResult r2 = AnalyzeSpatialSceneWithSensitivities(two, Values(two), parameters);
  const SpatialSensitivityResult r1 = AnalyzeSpatialSceneWithSensitivities(one, Values(one), parameters);
  ASSERT_TRUE(r2.report.ok()) << r2.report.failure.reason;
  ASSERT_TRUE(r1.report.ok()) << r1.report.failure.reason;
  ASSERT_EQ(r2.unavailable, "");
  ASSERT_EQ(r1.unavailable, "");
  ASSERT_EQ(r2.output_derivatives.size(), parameters.size());
  ASSERT_EQ(r1.output_derivatives.size(), parameters.size());
  double worst = 0.0;
  for (size_t i = 0; i < parameters.size(); ++i) {
    for (size_t k = 0; k < kDoorOutputs.size(); ++k) {
      const std::vector<double>&d2 = r2.output_derivatives[i][k], &d1 = r1.output_derivatives[i][k];
      ASSERT_EQ(d2.size(), d1.size());
      double scale = 0.0, difference = 0.0;
      for (size_t t = 0; t < d1.size(); ++t) {
        scale = std::max(scale, std::abs(d1[t]));
        difference = std::max(difference, std::abs(d2[t] - d1[t]));
      }
      ASSERT_GT(scale, sensitivity_testing::kNoDependence) << kDoorOutputs[k];
      worst = std::max(worst, difference / scale);
    }
  }
  EXPECT_LT(worst, kOneHingeAgreement);
  std::cout << "door on two hinges against one: derivatives differ by " << worst << " relative\n";
}

TEST(RedundantSensitivity, DrivenDoorOnTwoHingesAgreesWithCentralDifferences) {
  const spec::Scene scene = scene_text::Load(Door(true, true), "driven_door.scene.textproto");
  const spec::AnalysisReport plain = AnalyzeSpatialScene(scene, Values(scene));
  ASSERT_TRUE(plain.ok()) << plain.failure.reason;
  EXPECT_EQ(plain.formulation, spec::Formulation::kKinematic);
  const Agreement a = Compare(scene, {"mass", "span", "stiffness"}, {"edge_x", "edge_y", "force", "kinetic"});
  EXPECT_LT(a.worst_series, kDrivenAgreement);
  EXPECT_LT(a.worst_peak, kDrivenAgreement);
  std::cout << "driven door on two hinges: worst " << a.worst_series << " over the instants\n";
}

// A bob 0.5 m below two coaxial hinges (world y), swung out by a torque
// growing to `push` against gravity: sin(theta) = tau / (m g l), stable
// below 90 degrees. Five redundant rows.
constexpr char kBob[] = R"pb(
  parameters { name: "mass" value: 2 unit: "kg" }
  parameters { name: "push" value: 8 unit: "N m" }
  parameters { name: "span" value: 300 unit: "mm" }
  spatial {
    analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM
    ground_markers { name: "hinge" orientation { axis_angle { axis { x { value: 1 } } angle_deg: -90 } } }
    ground_markers {
      name: "hinge2" position_m { y { param: "span" } }
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
        name: "pivot2" position_m { y { param: "span" } z { value: 0.5 } }
        orientation { axis_angle { axis { x { value: 1 } } angle_deg: -90 } }
      }
      markers { name: "centre" }
    }
    joints { name: "hinge" kind: SPATIAL_JOINT_REVOLUTE a: "ground.hinge" b: "bob.pivot" }
    joints { name: "hinge2" kind: SPATIAL_JOINT_REVOLUTE a: "ground.hinge2" b: "bob.pivot2" }
    torques {
      name: "swing" body: "bob" torque_n_m { y { param: "push" } }
      tabulated { times_s: [0, 1] values: [0, 1] }
    }
    gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
  }
  outputs { name: "angle" joint_coordinate { joint: "hinge" } }
  outputs { name: "x" marker_position { marker: "bob.centre" axis: AXIS_X } }
  outputs { name: "z" marker_position { marker: "bob.centre" axis: AXIS_Z } }
  outputs { name: "potential" potential_energy {} }
  time_grid { start_s: 0.25 end_s: 1 points: 4 }
)pb";

TEST(RedundantSensitivity, BobOnTwoHingesSettlesWithTheDerivativesOfTheClosedForm) {
  const spec::Scene scene = scene_text::Load(kBob, "bob.scene.textproto");
  const Agreement a = Compare(scene, {"mass", "push", "span"}, {"angle", "x", "z", "potential"});
  EXPECT_LT(a.worst_series, kStaticAgreement);
  EXPECT_LT(a.worst_peak, kStaticAgreement);
  // d theta / d m and d theta / d tau of sin(theta) = tau / (m g l).
  const std::vector<double> p = Values(scene);
  const SpatialSensitivityResult r =
      AnalyzeSpatialSceneWithSensitivities(scene, p, {IndexOf(scene, "mass"), IndexOf(scene, "push")});
  ASSERT_TRUE(r.report.ok()) << r.report.failure.reason;
  ASSERT_EQ(r.unavailable, "");
  ASSERT_EQ(r.output_derivatives.size(), 2u);
  const double m = 2, g = 9.81, l = 0.5, push = 8;
  double worst = 0.0, largest = 0.0;
  for (size_t i = 0; i < r.report.times_s.size(); ++i) {
    const double tau = push * r.report.times_s[i];
    const double theta = std::asin(tau / (m * g * l)), cos_theta = std::cos(theta);
    const double by_mass = -tau / (m * m * g * l * cos_theta);
    const double by_push = r.report.times_s[i] / (m * g * l * cos_theta);
    // The joint angle's sign follows the hinge's axis: compare magnitudes
    // with the value's own sign.
    const double sign = scene_text::Series(r.report, "angle")[i] >= 0.0 ? 1.0 : -1.0;
    worst = std::max({worst, std::abs(r.output_derivatives[0][0][i] - sign * by_mass),
                      std::abs(r.output_derivatives[1][0][i] - sign * by_push)});
    largest = std::max({largest, std::abs(by_mass), std::abs(by_push)});
  }
  EXPECT_LT(worst / largest, kClosedFormAgreement);
  std::cout << "bob on two hinges: worst " << a.worst_series << " against central differences, " << worst / largest
            << " against the closed form\n";
}

// Bricard's linkage (spatial_mechanisms.h, the IFToMM benchmark) released
// under gravity, with respect to the mass of its third bar, over 2.5 s:
// the combinations are renewed within that time (the fixed ones failed at
// 2.47 s), so the sensitivities run across a restart. Against central
// differences of whole integrations at rtol 1e-11.
struct BricardRun {
  std::vector<VectorXd> q, v;
  std::vector<VectorXd> dq, dv;
  RedundantIntegrationCounters redundant;
};

constexpr int kBricardBar = 2;
constexpr double kBricardEnd_s = 2.5;
constexpr int kBricardIntervals = 50;
constexpr double kBricardTolerance = 1e-11;

Model BricardWithBarMass(double mass_kg) {
  Model m = ModelOf(oracle::Bricard());
  m.bodies[kBricardBar].mass_kg = mass_kg;
  return m;
}

BricardRun IntegrateBricard(double mass_kg, const multibody::ParameterPerturbation* parameter) {
  BricardRun run;
  const Model model = BricardWithBarMass(mass_kg);
  const SpatialSystem system(model);
  const SpatialAssembly a = AssembleSpatial(system, 0.0);
  EXPECT_TRUE(a.failure.ok()) << a.failure.reason;
  EXPECT_EQ(a.redundant_rows, 1);
  std::vector<double> times;
  for (int i = 0; i <= kBricardIntervals; ++i) times.push_back(kBricardEnd_s * i / kBricardIntervals);
  multibody::ForwardDynamicsOptions options;
  options.relative_tolerance = kBricardTolerance;
  options.absolute_tolerance = kBricardTolerance;
  multibody::ForwardSensitivityInput input;
  if (parameter != nullptr) {
    input.parameters = {*parameter};
    // The mass does not move the assembled start.
    input.q0 = {VectorXd::Zero(system.num_coordinates())};
    input.v0 = {VectorXd::Zero(system.num_coordinates())};
  }
  const auto record = [&](const multibody::MotionSample& s) {
    run.q.push_back(s.q);
    run.v.push_back(s.v);
    if (!s.sensitivities.empty()) {
      run.dq.push_back(s.sensitivities[0].q);
      run.dv.push_back(s.sensitivities[0].v);
    }
    return spec::AnalysisFailure::Ok();
  };
  multibody::ForwardDynamicsCounters counters;
  const spec::AnalysisFailure f =
      IntegrateWithRedundantRows(system, a.independent_combination, 0.0, a.q, a.v, times, options, record, &counters,
                                 &run.redundant, parameter != nullptr ? &input : nullptr);
  EXPECT_TRUE(f.ok()) << f.reason;
  EXPECT_EQ(run.q.size(), times.size());
  return run;
}

TEST(RedundantSensitivity, BricardLinkageAgreesWithCentralDifferencesAcrossARestart) {
  const double mass = 1.0, h = sensitivity_testing::kRelativeStep * mass;
  // The simulator's own variants at its usual relative step (1e-5).
  const double step = 1e-5 * mass;
  const Model plus_model = BricardWithBarMass(mass + step), minus_model = BricardWithBarMass(mass - step);
  const SpatialSystem plus(plus_model), minus(minus_model);
  const multibody::ParameterPerturbation parameter{&plus, &minus, step, mass, nullptr};
  const BricardRun run = IntegrateBricard(mass, &parameter);
  const BricardRun up = IntegrateBricard(mass + h, nullptr), down = IntegrateBricard(mass - h, nullptr);
  EXPECT_GE(run.redundant.restarts, 1);
  ASSERT_EQ(run.dq.size(), up.q.size());
  ASSERT_EQ(down.q.size(), up.q.size());
  double scale_q = 0.0, scale_v = 0.0, worst_q = 0.0, worst_v = 0.0;
  for (size_t i = 0; i < up.q.size(); ++i) {
    const VectorXd fd_q = (up.q[i] - down.q[i]) / (2 * h), fd_v = (up.v[i] - down.v[i]) / (2 * h);
    scale_q = std::max(scale_q, fd_q.cwiseAbs().maxCoeff());
    scale_v = std::max(scale_v, fd_v.cwiseAbs().maxCoeff());
    worst_q = std::max(worst_q, (run.dq[i] - fd_q).cwiseAbs().maxCoeff());
    worst_v = std::max(worst_v, (run.dv[i] - fd_v).cwiseAbs().maxCoeff());
  }
  ASSERT_GT(scale_q, sensitivity_testing::kNoDependence);  // the bar's mass shapes the fall
  EXPECT_LT(worst_q / scale_q, kDynamicAgreement);
  EXPECT_LT(worst_v / scale_v, kDynamicAgreement);
  std::cout << "Bricard linkage over " << kBricardEnd_s << " s (" << run.redundant.restarts
            << " restarts): coordinates' derivatives within " << worst_q / scale_q << ", velocities' within "
            << worst_v / scale_v << " of central differences (largest " << scale_q << ", " << scale_v << ")\n";
}

}  // namespace
}  // namespace mbopt::spatial
