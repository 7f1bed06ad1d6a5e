// Static equilibrium of spatial scenes (worker/spatial/
// spatial_static_equilibrium.h), from scene text to outputs, against closed
// forms: a block hung on a spring under a growing load, a pendulum held by
// a rotational spring (the balance solved here independently), a body on a
// bushing under a force and a torque, a driven crank whose static effort is
// the gravity torque, a bob swung out on two coaxial hinges (redundant
// joints) as on one; inverted pendulums accepted or refused by the
// stability check; the drawing of a static scene; the loading errors.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/spatial/scene_text_testing.h"
#include "worker/engine/analysis.h"
#include "worker/spatial/spatial_drawing.h"

namespace mbopt::spatial {
namespace {

using scene_text::Series;

constexpr char kFileLabel[] = "statics.scene.textproto";
spec::Scene Load(const std::string& text) { return scene_text::Load(text, kFileLabel); }
std::string LoadError(const std::string& text) { return scene_text::LoadError(text, kFileLabel); }

spec::AnalysisReport AnalyzeScene(const spec::Scene& scene, std::vector<double> p = {}) {
  if (p.empty()) p = scene.DefaultParameterValues();
  return engine::Analyze(scene, p);
}

// Newton on the equilibrium is converged to 1e-10 in its residuals (N, N m,
// m); positions of order 1 m and forces of order 10 N then agree with the
// closed forms to far better than this.
constexpr double kTolerance = 1e-8;

// A 1 kg block on a vertical slide hung from a spring (k = 100 N/m, L0 =
// 0.4 m), released 0.6 m below the anchor and pushed down by 5 t N: at
// rest, k (L - L0) = m g + 5 t.
constexpr char kHangingBlock[] = R"pb(
  spatial {
    analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM
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
      free_length_m { value: 0.4 } stiffness_n_per_m { value: 100 } damping_n_s_per_m { value: 3 }
    }
    point_forces {
      name: "push" at: "block.centre" force_n { z { value: -5 } }
      tabulated { times_s: [0, 2] values: [0, 2] }
    }
    gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
  }
  outputs { name: "z" marker_position { marker: "block.centre" axis: AXIS_Z } }
  outputs { name: "length" spring_length { spring: "spring" } }
  outputs { name: "force" spring_force { spring: "spring" } }
  outputs { name: "slide" joint_slide { joint: "slide" } }
  outputs { name: "fz" joint_reaction { joint: "slide" axis: AXIS_Z } }
  outputs { name: "potential" potential_energy {} }
  time_grid { start_s: 0 end_s: 2 points: 5 }
)pb";

TEST(SpatialStatics, BlockHungOnASpringStretchesItByTheLoadOverK) {
  const spec::Scene scene = Load(kHangingBlock);
  const spec::AnalysisReport r = AnalyzeScene(scene);
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  EXPECT_EQ(r.formulation, spec::Formulation::kStatic);
  ASSERT_EQ(r.times_s.size(), 5u);
  const double k = 100, l0 = 0.4, mg = 9.81;
  double worst = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double load = mg + 5 * r.times_s[i], length = l0 + load / k;
    worst = std::max({worst, std::abs(Series(r, "z")[i] + length), std::abs(Series(r, "length")[i] - length),
                      std::abs(Series(r, "force")[i] - load), std::abs(Series(r, "slide")[i] + length),
                      // The spring carries the load: the slide only guides.
                      std::abs(Series(r, "fz")[i]),
                      std::abs(Series(r, "potential")[i] - (-mg * length + 0.5 * k * (length - l0) * (length - l0)))});
  }
  EXPECT_LT(worst, kTolerance);
  std::cout << "block hung on a spring: largest error " << worst << "\n";
}

// A bob (2 kg, centre of mass l = 0.5 m below its hinge) on a revolute
// joint about world y, held by a rotational spring of stiffness k and free
// angle theta0, under gravity (0, 0, gz). The joint's angle theta turns the
// bob from hanging straight down towards -x; about the hinge, the spring's
// k (theta0 - theta) balances gravity's m (-gz) l sin(theta).
constexpr char kSprungPendulum[] = R"pb(
  parameters { name: "k" value: 5 unit: "N m/rad" }
  parameters { name: "theta0" value: 1 unit: "rad" }
  parameters { name: "gz" value: -9.81 unit: "m/s^2" }
  spatial {
    analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM
    ground_markers {
      name: "hinge"
      orientation { axis_angle { axis { x { value: 1 } } angle_deg: -90 } }
    }
    bodies {
      name: "bob"
      mass_kg { value: 2 }
      principal_inertia { moments_kg_m2 { x { value: 0.02 } y { value: 0.02 } z { value: 0.01 } } }
      position_m { z { value: -0.5 } }
      markers {
        name: "pivot" position_m { z { value: 0.5 } }
        orientation { axis_angle { axis { x { value: 1 } } angle_deg: -90 } }
      }
      markers { name: "centre" }
    }
    joints { name: "hinge" kind: SPATIAL_JOINT_REVOLUTE a: "ground.hinge" b: "bob.pivot" }
    rotational_springs {
      name: "torsion" joint: "hinge"
      stiffness_n_m_per_rad { param: "k" } damping_n_m_s_per_rad { value: 0.5 } free_angle_rad { param: "theta0" }
    }
    gravity { acceleration_m_per_s2 { z { param: "gz" } } }
  }
  outputs { name: "angle" joint_coordinate { joint: "hinge" } }
  outputs { name: "pitch" body_orientation { body: "bob" sequence: EULER_ZYX angle: 2 } }
  outputs { name: "x" marker_position { marker: "bob.centre" axis: AXIS_X } }
  outputs { name: "torque" rotational_spring_torque { spring: "torsion" } }
  outputs { name: "fx" joint_reaction { joint: "hinge" axis: AXIS_X } }
  outputs { name: "fz" joint_reaction { joint: "hinge" axis: AXIS_Z } }
  time_grid { start_s: 0 end_s: 1 points: 3 }
)pb";

// k (theta0 - theta) = w sin(theta) by bisection on [0, theta0] (the
// left side falls, the right rises there): independent of the engine.
double SprungPendulumAngle(double k, double theta0, double w) {
  double lo = 0, hi = theta0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (k * (theta0 - mid) > w * std::sin(mid) ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(SpatialStatics, PendulumOnARotationalSpringBalancesGravity) {
  const spec::AnalysisReport r = AnalyzeScene(Load(kSprungPendulum));
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  const double k = 5, theta0 = 1, m = 2, g = 9.81, l = 0.5;
  const double theta = SprungPendulumAngle(k, theta0, m * g * l);
  EXPECT_GT(theta, 0.2);  // far from both hanging straight and the free angle
  EXPECT_LT(theta, 0.8);
  double worst = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    worst = std::max({worst, std::abs(Series(r, "angle")[i] - theta), std::abs(Series(r, "pitch")[i] - theta),
                      std::abs(Series(r, "x")[i] + l * std::sin(theta)),
                      std::abs(Series(r, "torque")[i] - k * (theta0 - theta)),
                      // The hinge holds the bob's weight, nothing sideways.
                      std::abs(Series(r, "fx")[i]), std::abs(Series(r, "fz")[i] - m * g)});
  }
  EXPECT_LT(worst, kTolerance);
  std::cout << "pendulum on a rotational spring: angle " << theta << " rad, largest error " << worst << "\n";
}

// Upside down (gravity up) with the spring's free angle 0: straight up is an
// equilibrium, stable while k exceeds m g l = 9.81 N m/rad. The check sees
// the Euler parameters through the null space of the joint and norm rows.
TEST(SpatialStatics, InvertedPendulumIsStableOnlyWithAStiffEnoughSpring) {
  const spec::Scene scene = Load(kSprungPendulum);
  const spec::AnalysisReport stiff = AnalyzeScene(scene, {12.0, 0.0, 9.81});
  ASSERT_TRUE(stiff.ok()) << stiff.failure.reason;
  EXPECT_NEAR(Series(stiff, "angle")[0], 0.0, kTolerance);
  EXPECT_NEAR(Series(stiff, "fz")[2], -2 * 9.81, kTolerance);
  const spec::AnalysisReport soft = AnalyzeScene(scene, {8.0, 0.0, 9.81});
  ASSERT_FALSE(soft.ok());
  EXPECT_EQ(soft.failure.kind, spec::FailureKind::kModelValidity);
  EXPECT_NE(soft.failure.reason.find("the static equilibrium at t = 0 s is unstable"), std::string::npos)
      << soft.failure.reason;
  std::cout << "inverted pendulum, k = 8 N m/rad: " << soft.failure.reason << "\n";
}

// A 2 kg block on a bushing to ground (no gravity): stiffness 200, 800, 50
// N/m and 10, 10, 4 N m/rad. A force (4, -8, 2.5) t N at its centre
// deflects it by F / k along each axis; a torque 3 t N m about z turns it
// by psi = M / Kr, 43 deg at the end: about one axis the bushing's angle is
// the turn itself (a small-angle measure, sin(psi), gave sin(2 psi) =
// 2 M / Kr, which has no solution past M = Kr / 2).
constexpr char kBushingMount[] = R"pb(
  spatial {
    analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM
    ground_markers { name: "mount" }
    bodies {
      name: "block"
      mass_kg { value: 2 }
      principal_inertia { moments_kg_m2 { x { value: 0.1 } y { value: 0.2 } z { value: 0.25 } } }
      markers { name: "centre" }
    }
    bushings {
      name: "mount" a: "ground.mount" b: "block.centre"
      stiffness_n_per_m { x { value: 200 } y { value: 800 } z { value: 50 } }
      damping_n_s_per_m { x { value: 4 } }
      rotational_stiffness_n_m_per_rad { x { value: 10 } y { value: 10 } z { value: 4 } }
    }
    point_forces {
      name: "load" at: "block.centre" force_n { x { value: 4 } y { value: -8 } z { value: 2.5 } }
      tabulated { times_s: [0, 1] values: [0, 1] }
    }
    torques {
      name: "twist" body: "block" torque_n_m { z { value: 3 } }
      tabulated { times_s: [0, 1] values: [0, 1] }
    }
  }
  outputs { name: "x" marker_position { marker: "block.centre" axis: AXIS_X } }
  outputs { name: "y" marker_position { marker: "block.centre" axis: AXIS_Y } }
  outputs { name: "z" marker_position { marker: "block.centre" axis: AXIS_Z } }
  outputs { name: "yaw" body_orientation { body: "block" sequence: EULER_ZYX angle: 1 } }
  outputs { name: "pitch" body_orientation { body: "block" sequence: EULER_ZYX angle: 2 } }
  outputs { name: "roll" body_orientation { body: "block" sequence: EULER_ZYX angle: 3 } }
  outputs { name: "force_y" bushing_force { bushing: "mount" axis: AXIS_Y } }
  time_grid { start_s: 0 end_s: 1 points: 5 }
)pb";

TEST(SpatialStatics, BodyOnABushingDeflectsByLoadOverStiffness) {
  const spec::AnalysisReport r = AnalyzeScene(Load(kBushingMount));
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  double worst = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double t = r.times_s[i];
    const double psi = 3 * t / 4;
    worst = std::max({worst, std::abs(Series(r, "x")[i] - 4 * t / 200), std::abs(Series(r, "y")[i] + 8 * t / 800),
                      std::abs(Series(r, "z")[i] - 2.5 * t / 50), std::abs(Series(r, "yaw")[i] - psi),
                      std::abs(Series(r, "pitch")[i]), std::abs(Series(r, "roll")[i]),
                      std::abs(Series(r, "force_y")[i] - 8 * t)});
  }
  EXPECT_LT(worst, kTolerance);
  std::cout << "body on a bushing: largest error " << worst << "\n";
}

// A body on a bushing to ground (rotational stiffnesses 3, 5, 2 N m/rad,
// the frames at its centre with world axes) under a torque (1.5, -2, 1) t
// N m: at rest the bushing's couple on the body is minus the torque, at
// its x-y-z angles theta (29, -15, 40 deg at the end), and the angles
// satisfy the balance of their generalized forces, Kr theta = W(theta)^T
// T (W's columns x, Rx(theta_x) y, Rx(theta_x) Ry(theta_y) z).
constexpr char kTwistedOnABushing[] = R"pb(
  spatial {
    analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM
    ground_markers { name: "mount" }
    bodies {
      name: "block"
      mass_kg { value: 2 }
      principal_inertia { moments_kg_m2 { x { value: 0.1 } y { value: 0.2 } z { value: 0.25 } } }
      markers { name: "centre" }
    }
    bushings {
      name: "mount" a: "ground.mount" b: "block.centre"
      stiffness_n_per_m { x { value: 200 } y { value: 800 } z { value: 50 } }
      rotational_stiffness_n_m_per_rad { x { value: 3 } y { value: 5 } z { value: 2 } }
    }
    torques {
      name: "twist" body: "block" torque_n_m { x { value: 1.5 } y { value: -2 } z { value: 1 } }
      tabulated { times_s: [0, 1] values: [0, 1] }
    }
  }
  outputs { name: "mx" bushing_force { bushing: "mount" axis: AXIS_X moment: true } }
  outputs { name: "my" bushing_force { bushing: "mount" axis: AXIS_Y moment: true } }
  outputs { name: "mz" bushing_force { bushing: "mount" axis: AXIS_Z moment: true } }
  outputs { name: "ax" body_orientation { body: "block" sequence: EULER_XYZ angle: 1 } }
  outputs { name: "ay" body_orientation { body: "block" sequence: EULER_XYZ angle: 2 } }
  outputs { name: "az" body_orientation { body: "block" sequence: EULER_XYZ angle: 3 } }
  time_grid { start_s: 0 end_s: 1 points: 5 }
)pb";

TEST(SpatialStatics, BushingCoupleBalancesATorqueAtLargeRotations) {
  const spec::AnalysisReport r = AnalyzeScene(Load(kTwistedOnABushing));
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  double worst_couple = 0, worst_balance = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double t = r.times_s[i];
    const double torque[3] = {1.5 * t, -2 * t, 1 * t}, kr[3] = {3, 5, 2};
    worst_couple = std::max({worst_couple, std::abs(Series(r, "mx")[i] + torque[0]),
                             std::abs(Series(r, "my")[i] + torque[1]), std::abs(Series(r, "mz")[i] + torque[2])});
    const double a = Series(r, "ax")[i], b = Series(r, "ay")[i], c = Series(r, "az")[i];
    // W^T T, W's columns (1, 0, 0), (0, cos a, sin a), (sin b, -sin a cos b, cos a cos b).
    const double wt[3] = {torque[0], std::cos(a) * torque[1] + std::sin(a) * torque[2],
                          std::sin(b) * torque[0] - std::sin(a) * std::cos(b) * torque[1] +
                              std::cos(a) * std::cos(b) * torque[2]};
    const double angles[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) worst_balance = std::max(worst_balance, std::abs(kr[k] * angles[k] - wt[k]));
  }
  EXPECT_GT(std::abs(Series(r, "az").back()), 0.6);  // rad: far from small
  EXPECT_LT(worst_couple, kTolerance);
  EXPECT_LT(worst_balance, kTolerance);
  std::cout << "body twisted on a bushing: angles " << Series(r, "ax").back() << ", " << Series(r, "ay").back()
            << ", " << Series(r, "az").back() << " rad; largest error of the couple " << worst_couple
            << " N m, of the balance " << worst_balance << " N m\n";
}

// A hub on a hinge about world z whose rotational spring (k = 2 N m/rad)
// is free at theta0 = 4 pi + 0.2, wound two turns from the start, held by
// a torque T of -4 pi k (constant) plus 0.5 t N m about z: at rest the
// spring balances it, k (theta - theta0) = T, so theta = 0.2 + 0.25 t and
// the spring's torque is 4 pi k - 0.5 t. A measure in (-pi, pi] could not
// balance more than pi k.
constexpr char kWoundHub[] = R"pb(
  spatial {
    analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM
    ground_markers { name: "axle" }
    bodies {
      name: "hub"
      mass_kg { value: 1 }
      principal_inertia { moments_kg_m2 { x { value: 0.02 } y { value: 0.02 } z { value: 0.03 } } }
      markers { name: "centre" }
    }
    joints { name: "axle" kind: SPATIAL_JOINT_REVOLUTE a: "ground.axle" b: "hub.centre" }
    rotational_springs {
      name: "clock" joint: "axle"
      stiffness_n_m_per_rad { value: 2 } free_angle_rad { expr: "4 * pi + 0.2" }
    }
    torques { name: "hold" body: "hub" torque_n_m { z { expr: "-8 * pi" } } }
    torques {
      name: "extra" body: "hub" torque_n_m { z { value: 0.5 } }
      tabulated { times_s: [0, 1] values: [0, 1] }
    }
  }
  outputs { name: "angle" joint_coordinate { joint: "axle" } }
  outputs { name: "torque" rotational_spring_torque { spring: "clock" } }
  time_grid { start_s: 0 end_s: 1 points: 5 }
)pb";

TEST(SpatialStatics, SpringWoundTwoTurnsBalancesItsLoad) {
  const spec::AnalysisReport r = AnalyzeScene(Load(kWoundHub));
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  double worst = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double t = r.times_s[i];
    worst = std::max({worst, std::abs(Series(r, "angle")[i] - (0.2 + 0.25 * t)),
                      std::abs(Series(r, "torque")[i] - (8 * std::numbers::pi - 0.5 * t))});
  }
  EXPECT_LT(worst, kTolerance);
  std::cout << "hub on a spring wound two turns: largest error " << worst << "\n";
}

// The offset crank of spatial_forces_test (2 kg, centre of mass r = 0.15 m
// from the hinge axis, h = 0.05 m along it) turned slowly by its driver
// to theta = 3 t under gravity along -y: the driver holds the gravity
// torque m g r cos(theta), the hinge the weight (0, m g, 0) and the moment
// (-m g h, 0, 0) about it.
constexpr char kOffsetCrank[] = R"pb(
  spatial {
    analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM
    ground_markers { name: "hinge" }
    bodies {
      name: "crank"
      mass_kg { value: 2 }
      principal_inertia { moments_kg_m2 { x { value: 0.01 } y { value: 0.02 } z { value: 0.025 } } }
      position_m { x { value: 0.15 } z { value: 0.05 } }
      markers { name: "hub" position_m { x { value: -0.15 } z { value: -0.05 } } }
    }
    joints { name: "motor" kind: SPATIAL_JOINT_REVOLUTE a: "ground.hinge" b: "crank.hub" }
    drivers { joint: "motor" constant_rate { rate { value: 3 } } }
    gravity { acceleration_m_per_s2 { y { value: -9.81 } } }
  }
  outputs { name: "angle" joint_coordinate { joint: "motor" } }
  outputs { name: "effort" driver_effort { joint: "motor" } }
  outputs { name: "fx" joint_reaction { joint: "motor" axis: AXIS_X } }
  outputs { name: "fy" joint_reaction { joint: "motor" axis: AXIS_Y } }
  outputs { name: "fz" joint_reaction { joint: "motor" axis: AXIS_Z } }
  outputs { name: "mx" joint_reaction_moment { joint: "motor" axis: AXIS_X } }
  outputs { name: "my" joint_reaction_moment { joint: "motor" axis: AXIS_Y } }
  outputs { name: "mz" joint_reaction_moment { joint: "motor" axis: AXIS_Z } }
  time_grid { start_s: 0 end_s: 2 points: 9 }
)pb";

// A bob on a hinge about world y with a torsion spring (k = 20 N m/rad,
// free at 0) and a torque about y growing to 30 N m, swung out against
// gravity by theta where k theta + w sin(theta) = tau (w = m g l). Held by a
// second hinge on the same axis 0.3 m along it, the mechanism has five
// redundant rows; it settles where the single hinge does.
std::string SwungBob(bool second_hinge) {
  std::string text = R"pb(
  spatial {
    analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM
    ground_markers { name: "hinge" orientation { axis_angle { axis { x { value: 1 } } angle_deg: -90 } } }
    ground_markers {
      name: "hinge2" position_m { y { value: 0.3 } }
      orientation { axis_angle { axis { x { value: 1 } } angle_deg: -90 } }
    }
    bodies {
      name: "bob"
      mass_kg { value: 2 }
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
      markers { name: "centre" }
    }
    joints { name: "hinge" kind: SPATIAL_JOINT_REVOLUTE a: "ground.hinge" b: "bob.pivot" }
    rotational_springs { name: "torsion" joint: "hinge" stiffness_n_m_per_rad { value: 20 } }
    torques {
      name: "swing" body: "bob" torque_n_m { y { value: 30 } }
      tabulated { times_s: [0, 1] values: [0, 1] }
    }
    gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
)pb";
  if (second_hinge) text += R"pb(joints { name: "hinge2" kind: SPATIAL_JOINT_REVOLUTE a: "ground.hinge2" b: "bob.pivot2" })pb";
  text += R"pb(
  }
  outputs { name: "angle" joint_coordinate { joint: "hinge" } }
  outputs { name: "x" marker_position { marker: "bob.centre" axis: AXIS_X } }
  outputs { name: "z" marker_position { marker: "bob.centre" axis: AXIS_Z } }
  outputs { name: "torque" rotational_spring_torque { spring: "torsion" } }
  outputs { name: "potential" potential_energy {} }
  time_grid { start_s: 0 end_s: 1 points: 5 }
)pb";
  return text;
}

// k theta + w sin(theta) = tau by bisection on [0, pi/2] (the left side
// rises there): independent of the engine.
double SwungBobAngle(double k, double w, double tau) {
  double lo = 0, hi = M_PI / 2;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (k * mid + w * std::sin(mid) < tau ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(SpatialStatics, RedundantHingesSettleWhereOneHingeDoes) {
  const spec::AnalysisReport one = AnalyzeScene(Load(SwungBob(false)));
  const spec::AnalysisReport two = AnalyzeScene(Load(SwungBob(true)));
  ASSERT_TRUE(one.ok()) << one.failure.reason;
  ASSERT_TRUE(two.ok()) << two.failure.reason;
  const double k = 20, w = 2 * 9.81 * 0.5, l = 0.5;
  double worst = 0, apart = 0;
  for (size_t i = 0; i < two.times_s.size(); ++i) {
    const double theta = SwungBobAngle(k, w, 30 * two.times_s[i]);
    worst = std::max({worst, std::abs(Series(two, "angle")[i] - theta),
                      std::abs(Series(two, "x")[i] + l * std::sin(theta)),
                      std::abs(Series(two, "z")[i] + l * std::cos(theta)),
                      std::abs(Series(two, "torque")[i] + k * theta)});
    for (const char* name : {"angle", "x", "z", "torque", "potential"}) {
      apart = std::max(apart, std::abs(Series(two, name)[i] - Series(one, name)[i]));
    }
  }
  EXPECT_GT(Series(two, "angle").back(), 1.0);  // swung out past 57 degrees
  EXPECT_LT(worst, kTolerance);
  EXPECT_LT(apart, kTolerance);
  std::cout << "bob on two coaxial hinges: largest error against the closed form " << worst
            << ", against one hinge " << apart << "\n";
}

TEST(SpatialStatics, DrivenCrankHoldsTheGravityTorque) {
  const spec::AnalysisReport r = AnalyzeScene(Load(kOffsetCrank));
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  const double m = 2, g = 9.81, radius = 0.15, h = 0.05;
  double worst = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double theta = 3 * r.times_s[i];
    worst = std::max({worst, std::abs(std::remainder(Series(r, "angle")[i] - theta, 2 * std::acos(-1.0))),
                      std::abs(Series(r, "effort")[i] - m * g * radius * std::cos(theta)),
                      std::abs(Series(r, "fx")[i]), std::abs(Series(r, "fy")[i] - m * g), std::abs(Series(r, "fz")[i]),
                      std::abs(Series(r, "mx")[i] + m * g * h), std::abs(Series(r, "my")[i]),
                      std::abs(Series(r, "mz")[i])});
  }
  EXPECT_LT(worst, kTolerance);
  std::cout << "driven crank held statically: largest error " << worst << "\n";
}

// `mbopt-worker draw` draws the equilibrium at each instant, not a motion.
TEST(SpatialStatics, DrawingShowsTheEquilibria) {
  const spec::Scene scene = Load(kHangingBlock);
  const spec::SceneDrawing d = DrawSpatialScene(scene, scene.DefaultParameterValues());
  ASSERT_EQ(d.failure, "");
  ASSERT_EQ(d.times_s.size(), 5u);
  size_t centre = d.point_names.size();
  for (size_t k = 0; k < d.point_names.size(); ++k) {
    if (d.point_names[k] == "block.centre") centre = k;
  }
  ASSERT_LT(centre, d.point_names.size());
  for (size_t i = 0; i < d.times_s.size(); ++i) {
    EXPECT_NEAR(d.points_m[i][centre].z_m, -(0.4 + (9.81 + 5 * d.times_s[i]) / 100), kTolerance);
  }
}

// A static analysis has no motion: rates, accelerations and kinetic energy
// are refused, naming the file and the output; an unknown analysis too.
TEST(SpatialStatics, LoadingRefusesMotionOutputsOfAStaticScene) {
  const std::string base = kHangingBlock;
  auto with_output = [&](const std::string& output) {
    std::string text = base;
    text.replace(text.find("time_grid"), 0, output + "\n");
    return text;
  };
  for (const std::string output :
       {"outputs { name: \"v\" marker_velocity { marker: \"block.centre\" axis: AXIS_Z } }",
        "outputs { name: \"v\" joint_slide_rate { joint: \"slide\" } }",
        "outputs { name: \"v\" body_angular_velocity { body: \"block\" axis: AXIS_Z } }",
        "outputs { name: \"v\" kinetic_energy {} }"}) {
    const std::string error = LoadError(with_output(output));
    EXPECT_NE(error.find("statics.scene.textproto:"), std::string::npos) << error;
    EXPECT_NE(error.find("outputs[6]"), std::string::npos) << error;
    EXPECT_NE(error.find("output \"v\" is a rate, an acceleration or kinetic energy: a static-equilibrium analysis "
                         "has no motion"),
              std::string::npos)
        << error;
  }
  // Without the static analysis the same outputs load.
  std::string dynamic = with_output("outputs { name: \"v\" kinetic_energy {} }");
  dynamic.erase(dynamic.find("analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM"),
                std::string("analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM").size());
  EXPECT_TRUE(spec::io::ParseSceneText(dynamic, kFileLabel).ok());
}

}  // namespace
}  // namespace mbopt::spatial
