// Spatial force elements and the outputs that read them, from scene text to
// the engine's analysis, against closed forms: point forces and torques
// (world and body axes, constant and with time factors) giving known
// accelerations, a torsional pendulum on a rotational spring-damper, a body
// on a bushing oscillating at sqrt(k/m), joint reactions and a driver's
// effort against Newton-Euler by hand; and the loading errors of the new
// elements.
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

namespace mbopt::spatial {
namespace {

constexpr double kPi = std::numbers::pi;

using scene_text::Series;

constexpr char kFileLabel[] = "forces.scene.textproto";
spec::Scene Load(const std::string& text) { return scene_text::Load(text, kFileLabel); }
std::string LoadError(const std::string& text) { return scene_text::LoadError(text, kFileLabel); }

spec::AnalysisReport AnalyzeScene(const spec::Scene& scene, std::vector<double> p = {}) {
  if (p.empty()) p = scene.DefaultParameterValues();
  spec::AnalysisReport r = engine::Analyze(scene, p);
  EXPECT_TRUE(r.ok()) << r.failure.reason;
  return r;
}

// A free block (2 kg, no gravity) pushed by 4 N along world x, shaken by
// 3 N sin(5 t) along y, and twisted by 0.5 N m about z times a tabulated
// factor equal to t: a_x = 2, a_y = 1.5 sin(5 t), and about z (a principal
// axis, Izz = 0.25) omega = t^2, yaw t^3 / 3.
constexpr char kFreeBlock[] = R"pb(
  parameters { name: "push" value: 4 unit: "N" }
  spatial {
    bodies {
      name: "block"
      mass_kg { value: 2 }
      principal_inertia { moments_kg_m2 { x { value: 0.1 } y { value: 0.2 } z { value: 0.25 } } }
      markers { name: "centre" }
    }
    point_forces { name: "push" at: "block.centre" force_n { x { param: "push" } } }
    point_forces {
      name: "shake" at: "block.centre" force_n { y { value: 3 } }
      harmonic { amplitude { value: 1 } angular_frequency_rad_per_s { value: 5 } }
    }
    torques {
      name: "twist" body: "block" torque_n_m { z { value: 0.5 } }
      tabulated { times_s: [0, 2] values: [0, 2] }
    }
  }
  outputs { name: "x" marker_position { marker: "block.centre" axis: AXIS_X } }
  outputs { name: "y" marker_position { marker: "block.centre" axis: AXIS_Y } }
  outputs { name: "vy" marker_velocity { marker: "block.centre" axis: AXIS_Y } }
  outputs { name: "wz" body_angular_velocity { body: "block" axis: AXIS_Z } }
  outputs { name: "wz_body" body_angular_velocity { body: "block" axis: AXIS_Z body_axes: true } }
  outputs { name: "wx" body_angular_velocity { body: "block" axis: AXIS_X } }
  outputs { name: "yaw" body_orientation { body: "block" sequence: EULER_ZYX angle: 1 } }
  time_grid { start_s: 0 end_s: 1.5 points: 16 }
  integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-10 }
)pb";

TEST(SpatialForces, PointForcesAndTorqueWithTimeFactorsGiveKnownMotion) {
  const spec::Scene scene = Load(kFreeBlock);
  const spec::AnalysisReport r = AnalyzeScene(scene);
  ASSERT_TRUE(r.ok());
  double worst = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double t = r.times_s[i];
    const double y = 1.5 * (t / 5 - std::sin(5 * t) / 25), vy = 1.5 * (1 - std::cos(5 * t)) / 5;
    worst = std::max({worst, std::abs(Series(r, "x")[i] - t * t), std::abs(Series(r, "y")[i] - y),
                      std::abs(Series(r, "vy")[i] - vy), std::abs(Series(r, "wz")[i] - t * t),
                      std::abs(Series(r, "wz_body")[i] - t * t), std::abs(Series(r, "wx")[i]),
                      std::abs(Series(r, "yaw")[i] - t * t * t / 3)});
  }
  EXPECT_LT(worst, 1e-7);
  std::cout << "free block under loads: largest error " << worst << "\n";
  // The force follows its parameter: half the push, half the distance.
  const spec::AnalysisReport half = AnalyzeScene(scene, {2.0});
  EXPECT_NEAR(Series(half, "x").back(), 0.5 * 1.5 * 1.5, 1e-7);
}

// A body spinning freely about z at 4 rad/s pushed by 2 N along its own x
// axis (a follower force at its centre): a = (cos 4t, sin 4t) m/s^2, so
// v = (sin 4t, 1 - cos 4t) / 4. A wheel hinged at its centre about world z
// is pushed at a rim point (0, 0.2, 0) by -5 N along its own x: a constant
// torque of 1 N m, so with Izz = 0.25 its angle is 2 t^2.
constexpr char kFollowerForces[] = R"pb(
  spatial {
    ground_markers { name: "axle" }
    bodies {
      name: "spinner"
      mass_kg { value: 2 }
      principal_inertia { moments_kg_m2 { x { value: 0.1 } y { value: 0.2 } z { value: 0.25 } } }
      position_m { x { value: 1 } }
      angular_velocity_rad_per_s { z { value: 4 } }
      markers { name: "centre" }
    }
    bodies {
      name: "wheel"
      mass_kg { value: 3 }
      principal_inertia { moments_kg_m2 { x { value: 0.15 } y { value: 0.15 } z { value: 0.25 } } }
      markers { name: "hub" }
      markers { name: "rim" position_m { y { value: 0.2 } } }
    }
    joints { name: "axle" kind: SPATIAL_JOINT_REVOLUTE a: "ground.axle" b: "wheel.hub" }
    point_forces { name: "thrust" at: "spinner.centre" force_n { x { value: 2 } } axes: SPATIAL_LOAD_BODY_AXES }
    point_forces { name: "tangential" at: "wheel.rim" force_n { x { value: -5 } } axes: SPATIAL_LOAD_BODY_AXES }
  }
  outputs { name: "vx" marker_velocity { marker: "spinner.centre" axis: AXIS_X } }
  outputs { name: "vy" marker_velocity { marker: "spinner.centre" axis: AXIS_Y } }
  outputs { name: "angle" joint_coordinate { joint: "axle" } }
  time_grid { start_s: 0 end_s: 1.2 points: 13 }
  integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-10 }
)pb";

TEST(SpatialForces, BodyAxesForcesTurnWithTheirBody) {
  const spec::AnalysisReport r = AnalyzeScene(Load(kFollowerForces));
  ASSERT_TRUE(r.ok());
  double worst = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double t = r.times_s[i];
    worst = std::max({worst, std::abs(Series(r, "vx")[i] - std::sin(4 * t) / 4),
                      std::abs(Series(r, "vy")[i] - (1 - std::cos(4 * t)) / 4),
                      std::abs(std::remainder(Series(r, "angle")[i] - 2 * t * t, 2 * kPi))});
  }
  EXPECT_LT(worst, 1e-7);
  std::cout << "follower forces: largest error " << worst << "\n";
}

// A disc (Izz = 0.25 kg m^2) on a revolute joint whose axis is tilted by
// ZYX angles (30, 40, 0) deg, held by a rotational spring-damper (k = 4 N
// m/rad, c = 0.05 N m s/rad, free angle 0.3 rad), released at rest at angle
// 0: theta = 0.3 (1 - e^(-zeta W t) (cos Wd t + zeta / sqrt(1 - zeta^2)
// sin Wd t)), W = sqrt(k / I) = 4 rad/s, zeta = c / (2 sqrt(k I)).
constexpr char kTorsionalPendulum[] = R"pb(
  parameters { name: "damping" value: 0.05 unit: "N m s/rad" }
  spatial {
    ground_markers {
      name: "hinge"
      orientation { euler_angles { sequence: EULER_ZYX angles_deg: [30, 40, 0] } }
    }
    bodies {
      name: "disc"
      mass_kg { value: 5 }
      principal_inertia { moments_kg_m2 { x { value: 0.13 } y { value: 0.13 } z { value: 0.25 } } }
      orientation { euler_angles { sequence: EULER_ZYX angles_deg: [30, 40, 0] } }
      markers { name: "hub" }
    }
    joints { name: "hinge" kind: SPATIAL_JOINT_REVOLUTE a: "ground.hinge" b: "disc.hub" }
    rotational_springs {
      name: "torsion" joint: "hinge"
      stiffness_n_m_per_rad { value: 4 } damping_n_m_s_per_rad { param: "damping" } free_angle_rad { value: 0.3 }
    }
    gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
  }
  outputs { name: "angle" joint_coordinate { joint: "hinge" } }
  outputs { name: "rate" joint_rate { joint: "hinge" } }
  outputs { name: "torque" rotational_spring_torque { spring: "torsion" } }
  outputs { name: "kinetic" kinetic_energy {} }
  outputs { name: "potential" potential_energy {} }
  time_grid { start_s: 0 end_s: 3 points: 31 }
  integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-10 }
)pb";

TEST(SpatialForces, TorsionalPendulumSwingsAtSqrtKOverI) {
  const spec::Scene scene = Load(kTorsionalPendulum);
  const spec::AnalysisReport r = AnalyzeScene(scene);
  ASSERT_TRUE(r.ok());
  const double k = 4, c = 0.05, inertia = 0.25, w = std::sqrt(k / inertia), zeta = c / (2 * std::sqrt(k * inertia));
  const double wd = w * std::sqrt(1 - zeta * zeta);
  double worst_angle = 0, worst_torque = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double t = r.times_s[i];
    const double angle = 0.3 * (1 - std::exp(-zeta * w * t) *
                                        (std::cos(wd * t) + zeta / std::sqrt(1 - zeta * zeta) * std::sin(wd * t)));
    worst_angle = std::max(worst_angle, std::abs(Series(r, "angle")[i] - angle));
    worst_torque = std::max(worst_torque, std::abs(Series(r, "torque")[i] -
                                                   (-k * (Series(r, "angle")[i] - 0.3) - c * Series(r, "rate")[i])));
  }
  EXPECT_LT(worst_angle, 1e-7);
  EXPECT_LT(worst_torque, 1e-9);
  std::cout << "torsional pendulum: largest angle error " << worst_angle << " rad\n";
  // Undamped, the spring's energy and the disc's kinetic energy trade
  // places: the sum holds (gravity does no work on a disc turning about
  // its centre).
  const spec::AnalysisReport u = AnalyzeScene(scene, {0.0});
  ASSERT_TRUE(u.ok());
  const double energy0 = Series(u, "kinetic")[0] + Series(u, "potential")[0];
  double worst_energy = 0;
  for (size_t i = 0; i < u.times_s.size(); ++i) {
    worst_energy = std::max(worst_energy, std::abs(Series(u, "kinetic")[i] + Series(u, "potential")[i] - energy0));
    EXPECT_NEAR(Series(u, "angle")[i], 0.3 * (1 - std::cos(w * u.times_s[i])), 1e-7);
  }
  EXPECT_LT(worst_energy, 1e-8);
  // The spring's strain energy is in the potential: at the start, k 0.3^2 / 2
  // above the disc's gravity energy at the origin (zero).
  EXPECT_NEAR(Series(u, "potential")[0], 0.5 * k * 0.3 * 0.3, 1e-12);
}

// A 2 kg block on a bushing to ground whose markers' axes are turned 30 deg
// about z: stiffness 200, 800, 50 N/m and damping 4, 0, 0 N s/m along the
// markers' x, y, z; rotational stiffness 10, 10, 4 N m/rad. Launched at
// 0.5 m/s along the markers' x axis and turning at 1e-3 rad/s about z: it
// moves only along that axis, u = v0 / Wd e^(-zeta W t) sin Wd t with
// W = sqrt(200 / 2) = 10 rad/s and zeta = 0.1, and yaws by
// (1e-3 / 4) sin 4 t (W = sqrt(4 / 0.25)) under the moment -4 yaw.
constexpr char kBushingMount[] = R"pb(
  spatial {
    ground_markers { name: "mount" orientation { axis_angle { axis { z { value: 1 } } angle_deg: 30 } } }
    bodies {
      name: "block"
      mass_kg { value: 2 }
      principal_inertia { moments_kg_m2 { x { value: 0.1 } y { value: 0.2 } z { value: 0.25 } } }
      velocity_m_per_s { x { expr: "0.5 * cos(pi / 6)" } y { expr: "0.5 * sin(pi / 6)" } }
      angular_velocity_rad_per_s { z { value: 1e-3 } }
      markers { name: "centre" }
      markers { name: "mount" orientation { axis_angle { axis { z { value: 1 } } angle_deg: 30 } } }
    }
    bushings {
      name: "mount" a: "ground.mount" b: "block.mount"
      stiffness_n_per_m { x { value: 200 } y { value: 800 } z { value: 50 } }
      damping_n_s_per_m { x { value: 4 } }
      rotational_stiffness_n_m_per_rad { x { value: 10 } y { value: 10 } z { value: 4 } }
    }
  }
  outputs { name: "x" marker_position { marker: "block.centre" axis: AXIS_X } }
  outputs { name: "y" marker_position { marker: "block.centre" axis: AXIS_Y } }
  outputs { name: "z" marker_position { marker: "block.centre" axis: AXIS_Z } }
  outputs { name: "yaw" body_orientation { body: "block" sequence: EULER_ZYX angle: 1 } }
  outputs { name: "force_x" bushing_force { bushing: "mount" axis: AXIS_X } }
  outputs { name: "force_y" bushing_force { bushing: "mount" axis: AXIS_Y } }
  outputs { name: "moment_z" bushing_force { bushing: "mount" axis: AXIS_Z moment: true } }
  outputs { name: "ux_rate" marker_velocity { marker: "block.centre" axis: AXIS_X } }
  outputs { name: "uy_rate" marker_velocity { marker: "block.centre" axis: AXIS_Y } }
  time_grid { start_s: 0 end_s: 2 points: 41 }
  integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-12 }
)pb";

TEST(SpatialForces, BodyOnABushingOscillatesAtSqrtKOverM) {
  const spec::AnalysisReport r = AnalyzeScene(Load(kBushingMount));
  ASSERT_TRUE(r.ok());
  const double w = 10, zeta = 0.1, wd = w * std::sqrt(1 - zeta * zeta), v0 = 0.5;
  const double c30 = std::cos(kPi / 6), s30 = std::sin(kPi / 6);
  double worst_u = 0, worst_across = 0, worst_yaw = 0, worst_force = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double t = r.times_s[i];
    const double x = Series(r, "x")[i], y = Series(r, "y")[i];
    const double u = c30 * x + s30 * y, across = -s30 * x + c30 * y;
    const double u_rate = c30 * Series(r, "ux_rate")[i] + s30 * Series(r, "uy_rate")[i];
    const double expected = v0 / wd * std::exp(-zeta * w * t) * std::sin(wd * t);
    worst_u = std::max(worst_u, std::abs(u - expected));
    worst_across = std::max({worst_across, std::abs(across), std::abs(Series(r, "z")[i])});
    const double yaw = 1e-3 / 4 * std::sin(4 * t);
    worst_yaw = std::max(worst_yaw, std::abs(Series(r, "yaw")[i] - yaw));
    worst_force = std::max({worst_force, std::abs(Series(r, "force_x")[i] - (-200 * u - 4 * u_rate)),
                            std::abs(Series(r, "force_y")[i])});
    EXPECT_NEAR(Series(r, "moment_z")[i], -4 * Series(r, "yaw")[i], 1e-12);
  }
  EXPECT_LT(worst_u, 1e-8);
  EXPECT_LT(worst_across, 1e-8);
  EXPECT_LT(worst_yaw, 1e-3 / 4 * 1e-5);
  EXPECT_LT(worst_force, 1e-6);
  std::cout << "bushing mount: largest error along the axis " << worst_u << " m, across it " << worst_across
            << " m, of the yaw " << worst_yaw << " rad, of the force " << worst_force << " N\n";
}

// A rotor (Izz = 0.25 kg m^2) on a bushing to ground whose frames' axes are
// turned by 50 deg about (1, 2, 3), the body's frame turned by -70 deg about
// its z axis (a principal axis) from the ground's: released at rest, it
// turns about that axis alone with the angle theta = -70 deg cos(W t),
// W = sqrt(kz / Izz) = 4 rad/s, under the moment -kz theta (a small-angle
// measure's -kz sin(theta) is 23 % short at 70 deg and changes the
// period); its energy kz theta^2 / 2 trades with Izz theta'^2 / 2.
constexpr char kTurnedRotor[] = R"pb(
  spatial {
    ground_markers {
      name: "mount"
      orientation { axis_angle { axis { x { value: 1 } y { value: 2 } z { value: 3 } } angle_deg: 50 } }
    }
    bodies {
      name: "rotor"
      mass_kg { value: 2 }
      principal_inertia { moments_kg_m2 { x { value: 0.1 } y { value: 0.2 } z { value: 0.25 } } }
      orientation { axis_angle { axis { x { value: 1 } y { value: 2 } z { value: 3 } } angle_deg: 50 } }
      markers { name: "mount" orientation { axis_angle { axis { z { value: 1 } } angle_deg: -70 } } }
    }
    bushings {
      name: "mount" a: "ground.mount" b: "rotor.mount"
      stiffness_n_per_m { x { value: 200 } y { value: 800 } z { value: 50 } }
      rotational_stiffness_n_m_per_rad { x { value: 10 } y { value: 6 } z { value: 4 } }
    }
  }
  outputs { name: "moment_x" bushing_force { bushing: "mount" axis: AXIS_X moment: true } }
  outputs { name: "moment_y" bushing_force { bushing: "mount" axis: AXIS_Y moment: true } }
  outputs { name: "moment_z" bushing_force { bushing: "mount" axis: AXIS_Z moment: true } }
  outputs { name: "wz" body_angular_velocity { body: "rotor" axis: AXIS_Z body_axes: true } }
  outputs { name: "wx" body_angular_velocity { body: "rotor" axis: AXIS_X body_axes: true } }
  outputs { name: "potential" potential_energy {} }
  time_grid { start_s: 0 end_s: 3 points: 31 }
  integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-10 }
)pb";

TEST(SpatialForces, BushingTurnedAboutOneAxisPullsBackWithStiffnessTimesAngle) {
  const spec::AnalysisReport r = AnalyzeScene(Load(kTurnedRotor));
  ASSERT_TRUE(r.ok());
  const double theta0 = 70 * kPi / 180, w = 4, kz = 4;
  double worst_moment = 0, worst_rate = 0, worst_energy = 0, worst_across = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double t = r.times_s[i], theta = -theta0 * std::cos(w * t);
    worst_moment = std::max(worst_moment, std::abs(Series(r, "moment_z")[i] + kz * theta));
    worst_rate = std::max(worst_rate, std::abs(Series(r, "wz")[i] - theta0 * w * std::sin(w * t)));
    worst_energy = std::max(worst_energy, std::abs(Series(r, "potential")[i] - 0.5 * kz * theta * theta));
    worst_across = std::max({worst_across, std::abs(Series(r, "moment_x")[i]), std::abs(Series(r, "moment_y")[i]),
                             std::abs(Series(r, "wx")[i])});
  }
  EXPECT_LT(worst_moment, 1e-7);  // N m, of 4.9
  EXPECT_LT(worst_rate, 1e-7);    // rad/s, of 4.9
  EXPECT_LT(worst_energy, 1e-7);  // J, of 3.0
  EXPECT_LT(worst_across, 1e-9);
  std::cout << "rotor turned 70 deg on a bushing: largest error of the moment " << worst_moment
            << " N m, of the rate " << worst_rate << " rad/s, of the energy " << worst_energy << " J\n";
}

// An undamped body on a bushing released with its frame turned by the
// x-y-z angles (40, -30, 55) deg from the ground's and spinning at
// (1, -0.5, 0.8) rad/s: the bushing's strain energy at the start is
// (kx 40^2 + ky 30^2 + kz 55^2) (pi / 180)^2 / 2 (its angles are those
// angles), and kinetic plus strain energy holds over the motion (the
// moments are the energy's exact gradient).
constexpr char kTumblingOnABushing[] = R"pb(
  spatial {
    ground_markers { name: "mount" position_m { z { value: 0.1 } } }
    bodies {
      name: "body"
      mass_kg { value: 1.5 }
      principal_inertia { moments_kg_m2 { x { value: 0.08 } y { value: 0.05 } z { value: 0.03 } } }
      angular_velocity_rad_per_s { x { value: 1 } y { value: -0.5 } z { value: 0.8 } }
      markers {
        name: "mount" position_m { z { value: 0.1 } }
        orientation { euler_angles { sequence: EULER_XYZ angles_deg: [40, -30, 55] } }
      }
    }
    bushings {
      name: "mount" a: "ground.mount" b: "body.mount"
      stiffness_n_per_m { x { value: 400 } y { value: 250 } z { value: 600 } }
      rotational_stiffness_n_m_per_rad { x { value: 3 } y { value: 5 } z { value: 2 } }
    }
  }
  outputs { name: "kinetic" kinetic_energy {} }
  outputs { name: "potential" potential_energy {} }
  outputs { name: "wx" body_angular_velocity { body: "body" axis: AXIS_X } }
  time_grid { start_s: 0 end_s: 2 points: 41 }
  integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-10 }
)pb";

TEST(SpatialForces, UndampedBushingKeepsItsEnergyAtLargeRotations) {
  const spec::AnalysisReport r = AnalyzeScene(Load(kTumblingOnABushing));
  ASSERT_TRUE(r.ok());
  const double d = kPi / 180;
  const double strain0 = 0.5 * (3 * 40 * 40 + 5 * 30 * 30 + 2 * 55 * 55) * d * d;
  EXPECT_NEAR(Series(r, "potential")[0], strain0, 1e-12);
  const double energy0 = Series(r, "kinetic")[0] + Series(r, "potential")[0];
  double worst = 0, swing = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    worst = std::max(worst, std::abs(Series(r, "kinetic")[i] + Series(r, "potential")[i] - energy0));
    swing = std::max(swing, std::abs(Series(r, "wx")[i] - Series(r, "wx")[0]));
  }
  EXPECT_GT(swing, 1.0);                 // rad/s: it tumbles
  // J, of 2.4: the integration's drift at tolerance 1e-10 (1.8e-8 to
  // 2.5e-8 J measured, as the Newton matrix changed); a measure whose
  // moments are not the energy's gradient drifts by orders more.
  EXPECT_LT(worst, 1e-7 * energy0);
  std::cout << "body tumbling on a bushing: energy " << energy0 << " J, largest change " << worst << " J\n";
}

// The rotor of kTurnedRotor turned 80 deg about its frame's y axis (the
// middle of the x-y-z angles) and spinning further at 1 rad/s with no
// stiffness about y: the angle reaches the bushing's 85 deg limit near
// t = 0.087 s and the analysis ends there, naming the bushing.
constexpr char kBushingPastItsLimit[] = R"pb(
  spatial {
    ground_markers { name: "mount" }
    bodies {
      name: "rotor"
      mass_kg { value: 2 }
      principal_inertia { moments_kg_m2 { x { value: 0.1 } y { value: 0.2 } z { value: 0.25 } } }
      angular_velocity_rad_per_s { y { value: 1 } }
      markers { name: "mount" orientation { axis_angle { axis { y { value: 1 } } angle_deg: 80 } } }
    }
    bushings {
      name: "mount" a: "ground.mount" b: "rotor.mount"
      stiffness_n_per_m { x { value: 200 } y { value: 800 } z { value: 50 } }
      rotational_stiffness_n_m_per_rad { x { value: 10 } z { value: 4 } }
    }
  }
  outputs { name: "wy" body_angular_velocity { body: "rotor" axis: AXIS_Y } }
  time_grid { start_s: 0 end_s: 1 points: 11 }
  integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-10 }
)pb";

TEST(SpatialForces, BushingNearItsSingularMiddleAngleEndsTheAnalysisNamingIt) {
  const spec::AnalysisReport r = engine::Analyze(Load(kBushingPastItsLimit), {});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kModelValidity);
  EXPECT_NE(r.failure.reason.find("bushing 'mount'"), std::string::npos) << r.failure.reason;
  EXPECT_NE(r.failure.reason.find("t = 0.0872"), std::string::npos) << r.failure.reason;
  std::cout << "bushing past its limit: " << r.failure.reason << "\n";
}

// The same limit in a kinematic analysis, whose motion does not read the
// bushing: a hinge about world y driven from 80 deg at 1 rad/s turns the
// bushing's frame about its y axis; the analysis ends at the first instant
// past 85 deg (t = 0.0873 s), 0.09 s, naming the bushing.
constexpr char kDrivenPastTheLimit[] = R"pb(
  spatial {
    ground_markers { name: "mount" }
    ground_markers { name: "hinge" orientation { axis_angle { axis { x { value: 1 } } angle_deg: -90 } } }
    bodies {
      name: "rotor"
      mass_kg { value: 2 }
      principal_inertia { moments_kg_m2 { x { value: 0.1 } y { value: 0.2 } z { value: 0.25 } } }
      orientation { axis_angle { axis { y { value: 1 } } angle_deg: 80 } }
      markers { name: "mount" }
      markers { name: "pivot" orientation { axis_angle { axis { x { value: 1 } } angle_deg: -90 } } }
    }
    joints { name: "hinge" kind: SPATIAL_JOINT_REVOLUTE a: "ground.hinge" b: "rotor.pivot" }
    drivers { joint: "hinge" constant_rate { start { expr: "80 * pi / 180" } rate { value: 1 } } }
    bushings {
      name: "mount" a: "ground.mount" b: "rotor.mount"
      rotational_stiffness_n_m_per_rad { x { value: 10 } y { value: 6 } z { value: 4 } }
    }
  }
  outputs { name: "moment_y" bushing_force { bushing: "mount" axis: AXIS_Y moment: true } }
  time_grid { start_s: 0 end_s: 0.2 points: 21 }
)pb";

TEST(SpatialForces, KinematicAnalysisEndsWhereABushingReachesItsLimit) {
  const spec::AnalysisReport r = engine::Analyze(Load(kDrivenPastTheLimit), {});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.formulation, spec::Formulation::kKinematic);
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kModelValidity);
  EXPECT_NE(r.failure.reason.find("bushing 'mount'"), std::string::npos) << r.failure.reason;
  EXPECT_NE(r.failure.reason.find("t = 0.09 s"), std::string::npos) << r.failure.reason;
  // Up to 0.08 s it runs, the moment about y -6 times the angle.
  std::string before = kDrivenPastTheLimit;
  const std::string grid = "end_s: 0.2 points: 21";
  before.replace(before.find(grid), grid.size(), "end_s: 0.08 points: 9");
  const spec::AnalysisReport ok = AnalyzeScene(Load(before));
  ASSERT_TRUE(ok.ok());
  for (size_t i = 0; i < ok.times_s.size(); ++i) {
    EXPECT_NEAR(Series(ok, "moment_y")[i], -6 * (80 * kPi / 180 + ok.times_s[i]), 1e-9);
  }
}

// A flywheel (Izz = 0.25 kg m^2) on a hinge about world z with a torsion
// spring (k = 4 N m/rad, undamped): theta'' = -W^2 (theta - theta0), W = 4
// rad/s. Released at rest at theta = 0 with the spring free at theta0 = 5
// pi (wound two and a half turns), theta = theta0 (1 - cos W t) swings
// through five turns and back; free at 0 and started at 24 pi rad/s, theta
// = 6 pi sin(W t), three turns either way. Over 5 s (three periods) the
// hinge's angle (in (-pi, pi], compared modulo a turn), its rate and the
// spring's torque -k (theta - theta0) follow the closed forms, and the
// energy holds: the spring's angle counts the turns (a measure in (-pi,
// pi] flips the torque at half a turn). At tolerance 1e-12: at 1e-10 the
// angle's error over the fifteen turns it travels is 1.7e-6 rad (the
// integrator's phase error, 1e-8 of the way).
constexpr char kWoundFlywheel[] = R"pb(
  parameters { name: "free_angle" value: 0 unit: "rad" }
  parameters { name: "spin" value: 0 unit: "rad/s" }
  spatial {
    ground_markers { name: "axle" }
    bodies {
      name: "flywheel"
      mass_kg { value: 5 }
      principal_inertia { moments_kg_m2 { x { value: 0.13 } y { value: 0.13 } z { value: 0.25 } } }
      angular_velocity_rad_per_s { z { param: "spin" } }
      markers { name: "hub" }
    }
    joints { name: "axle" kind: SPATIAL_JOINT_REVOLUTE a: "ground.axle" b: "flywheel.hub" }
    rotational_springs {
      name: "torsion" joint: "axle"
      stiffness_n_m_per_rad { value: 4 } free_angle_rad { param: "free_angle" }
    }
  }
  outputs { name: "angle" joint_coordinate { joint: "axle" } }
  outputs { name: "rate" joint_rate { joint: "axle" } }
  outputs { name: "torque" rotational_spring_torque { spring: "torsion" } }
  outputs { name: "kinetic" kinetic_energy {} }
  outputs { name: "potential" potential_energy {} }
  time_grid { start_s: 0 end_s: 5 points: 101 }
  integrator { relative_tolerance: 1e-12 absolute_tolerance: 1e-12 }
)pb";

TEST(SpatialForces, FlywheelOnASpringWoundTurnsSwingsAtSqrtKOverI) {
  const spec::Scene scene = Load(kWoundFlywheel);
  const double k = 4, w = 4;
  spec::AnalysisReport wound_report;
  for (const bool wound : {true, false}) {
    const double theta0 = wound ? 5 * kPi : 0, spin = wound ? 0 : 24 * kPi;
    const spec::AnalysisReport r = AnalyzeScene(scene, {theta0, spin});
    ASSERT_TRUE(r.ok());
    if (wound) wound_report = r;
    double worst_angle = 0, worst_rate = 0, worst_torque = 0, worst_energy = 0, widest = 0;
    const double energy0 = Series(r, "kinetic")[0] + Series(r, "potential")[0];
    for (size_t i = 0; i < r.times_s.size(); ++i) {
      const double t = r.times_s[i];
      const double theta = wound ? theta0 * (1 - std::cos(w * t)) : spin / w * std::sin(w * t);
      const double rate = wound ? theta0 * w * std::sin(w * t) : spin * std::cos(w * t);
      widest = std::max(widest, std::abs(theta - theta0));
      worst_angle = std::max(worst_angle, std::abs(std::remainder(Series(r, "angle")[i] - theta, 2 * kPi)));
      worst_rate = std::max(worst_rate, std::abs(Series(r, "rate")[i] - rate));
      worst_torque = std::max(worst_torque, std::abs(Series(r, "torque")[i] + k * (theta - theta0)));
      worst_energy =
          std::max(worst_energy, std::abs(Series(r, "kinetic")[i] + Series(r, "potential")[i] - energy0));
    }
    EXPECT_GT(widest, 2 * 2 * kPi);  // the spring is wound by more than two turns
    EXPECT_LT(worst_angle, 1e-7);    // rad
    EXPECT_LT(worst_rate, 4e-7);     // rad/s, of 63 and 75
    EXPECT_LT(worst_torque, 4e-7);   // N m, of 63 and 75
    EXPECT_LT(worst_energy, 1e-8 * energy0);
    std::cout << (wound ? "flywheel released wound 2.5 turns" : "flywheel started at 24 pi rad/s")
              << ": largest error of the angle " << worst_angle << " rad, of the rate " << worst_rate
              << " rad/s, of the torque " << worst_torque << " N m, of the energy " << worst_energy << " J of "
              << energy0 << "\n";
  }
  // A rerun evaluates the same states in the same order: the same bits.
  const spec::AnalysisReport again = AnalyzeScene(scene, {5 * kPi, 0.0});
  EXPECT_EQ(Series(wound_report, "torque"), Series(again, "torque"));
  EXPECT_EQ(Series(wound_report, "angle"), Series(again, "angle"));
}

// The wound flywheel on the explicit path, which shares its step loop with
// the planar engine: the turns are counted the same way (the spring's
// torque follows -k (theta - theta0) through the five turns).
TEST(SpatialForces, FlywheelOnASpringWoundTurnsOnTheExplicitPath) {
  std::string text = kWoundFlywheel;
  const std::string block = "integrator {";
  text.insert(text.find(block) + block.size(), " method: EXPLICIT_RUNGE_KUTTA");
  const spec::Scene scene = Load(text);
  ASSERT_EQ(scene.integrator.method, spec::IntegratorMethod::kExplicitRungeKutta);
  const double k = 4, w = 4, theta0 = 5 * kPi;
  const spec::AnalysisReport r = AnalyzeScene(scene, {theta0, 0.0});
  ASSERT_TRUE(r.ok());
  double worst_angle = 0, worst_torque = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double theta = theta0 * (1 - std::cos(w * r.times_s[i]));
    worst_angle = std::max(worst_angle, std::abs(std::remainder(Series(r, "angle")[i] - theta, 2 * kPi)));
    worst_torque = std::max(worst_torque, std::abs(Series(r, "torque")[i] + k * (theta - theta0)));
  }
  EXPECT_LT(worst_angle, 1e-7);   // rad
  EXPECT_LT(worst_torque, 4e-7);  // N m, of 63
  std::cout << "wound flywheel, explicit path: largest error of the angle " << worst_angle << " rad, of the torque "
            << worst_torque << " N m\n";
}

// The flywheel driven at 3 rad/s through two turns (kinematic analysis)
// against its spring (k = 4 N m/rad, c = 0.5 N m s/rad, free at 0.5 rad):
// the spring's torque -k (3 t - 0.5) - 3 c over the whole way.
constexpr char kDrivenWinding[] = R"pb(
  spatial {
    ground_markers { name: "axle" }
    bodies {
      name: "flywheel"
      mass_kg { value: 5 }
      principal_inertia { moments_kg_m2 { x { value: 0.13 } y { value: 0.13 } z { value: 0.25 } } }
      markers { name: "hub" }
    }
    joints { name: "axle" kind: SPATIAL_JOINT_REVOLUTE a: "ground.axle" b: "flywheel.hub" }
    drivers { joint: "axle" constant_rate { rate { value: 3 } } }
    rotational_springs {
      name: "torsion" joint: "axle"
      stiffness_n_m_per_rad { value: 4 } damping_n_m_s_per_rad { value: 0.5 } free_angle_rad { value: 0.5 }
    }
  }
  outputs { name: "torque" rotational_spring_torque { spring: "torsion" } }
  outputs { name: "potential" potential_energy {} }
  time_grid { start_s: 0 end_s: 4.18879 points: 49 }
)pb";

TEST(SpatialForces, DrivenSpringReportsItsTorqueThroughTwoTurns) {
  const spec::AnalysisReport r = AnalyzeScene(Load(kDrivenWinding));
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.formulation, spec::Formulation::kKinematic);
  double worst_torque = 0, worst_energy = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double deflection = 3 * r.times_s[i] - 0.5;
    worst_torque = std::max(worst_torque, std::abs(Series(r, "torque")[i] - (-4 * deflection - 0.5 * 3)));
    worst_energy = std::max(worst_energy, std::abs(Series(r, "potential")[i] - 0.5 * 4 * deflection * deflection));
  }
  EXPECT_GT(3 * r.times_s.back(), 2 * 2 * kPi - 1e-4);  // two turns
  EXPECT_LT(worst_torque, 1e-9);
  EXPECT_LT(worst_energy, 1e-9);
  std::cout << "spring driven through two turns: largest error of the torque " << worst_torque << " N m\n";
}

// A crank (2 kg, CoM at r = 0.15 m from the hinge axis and h = 0.05 m along
// it) driven at w = 3 rad/s about world z, gravity along -y. Newton-Euler
// about the hinge by hand, with theta = w t:
//   driver torque = m g r cos(theta),
//   force on the crank = (-m w^2 r cos, -m w^2 r sin + m g, 0),
//   moment on it about the hinge = (m w^2 h r sin - m g h, -m w^2 h r cos, 0).
constexpr char kOffsetCrank[] = R"pb(
  spatial {
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
  outputs { name: "effort" driver_effort { joint: "motor" } }
  outputs { name: "fx" joint_reaction { joint: "motor" axis: AXIS_X } }
  outputs { name: "fy" joint_reaction { joint: "motor" axis: AXIS_Y } }
  outputs { name: "fz" joint_reaction { joint: "motor" axis: AXIS_Z } }
  outputs { name: "mx" joint_reaction_moment { joint: "motor" axis: AXIS_X } }
  outputs { name: "my" joint_reaction_moment { joint: "motor" axis: AXIS_Y } }
  outputs { name: "mz" joint_reaction_moment { joint: "motor" axis: AXIS_Z } }
  time_grid { start_s: 0 end_s: 2 points: 21 }
  integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-10 }
)pb";

TEST(SpatialForces, DrivenCrankEffortAndReactionsMatchNewtonEuler) {
  const spec::AnalysisReport r = AnalyzeScene(Load(kOffsetCrank));
  ASSERT_TRUE(r.ok());
  const double m = 2, g = 9.81, w = 3, radius = 0.15, h = 0.05;
  double worst_effort = 0, worst_force = 0, worst_moment = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double a = w * r.times_s[i], c = std::cos(a), s = std::sin(a);
    worst_effort = std::max(worst_effort, std::abs(Series(r, "effort")[i] - m * g * radius * c));
    worst_force = std::max({worst_force, std::abs(Series(r, "fx")[i] + m * w * w * radius * c),
                            std::abs(Series(r, "fy")[i] - (-m * w * w * radius * s + m * g)),
                            std::abs(Series(r, "fz")[i])});
    worst_moment = std::max({worst_moment, std::abs(Series(r, "mx")[i] - (m * w * w * h * radius * s - m * g * h)),
                             std::abs(Series(r, "my")[i] + m * w * w * h * radius * c), std::abs(Series(r, "mz")[i])});
  }
  // The multipliers are outside the integrator's error test: some 1e-7
  // relative at this tolerance (docs/physics.md section 8), against
  // efforts and forces of a few N m and N.
  EXPECT_LT(worst_effort, 3e-6);
  EXPECT_LT(worst_force, 3e-6);
  EXPECT_LT(worst_moment, 3e-6);
  std::cout << "offset crank: largest error of the effort " << worst_effort << " N m, of the reaction force "
            << worst_force << " N, of its moment " << worst_moment << " N m\n";
}

// The conical pendulum of spatial_scene_test (a bob on a rod of l = 0.8 m
// at 0.6 rad from the vertical): the rod's pull on the bob is its tension
// m g / cos(theta) along the rod, towards the pivot; a spherical joint
// carries no moment.
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
      markers { name: "rod_end" position_m { z { param: "l" } } }
    }
    joints { name: "pivot" kind: SPATIAL_JOINT_SPHERICAL a: "ground.pivot" b: "bob.rod_end" }
    gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
  }
  outputs { name: "fx" joint_reaction { joint: "pivot" axis: AXIS_X } }
  outputs { name: "fy" joint_reaction { joint: "pivot" axis: AXIS_Y } }
  outputs { name: "fz" joint_reaction { joint: "pivot" axis: AXIS_Z } }
  outputs { name: "mx" joint_reaction_moment { joint: "pivot" axis: AXIS_X } }
  outputs { name: "my" joint_reaction_moment { joint: "pivot" axis: AXIS_Y } }
  outputs { name: "mz" joint_reaction_moment { joint: "pivot" axis: AXIS_Z } }
  time_grid { start_s: 0 end_s: 1 points: 21 }
  integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-10 }
)pb";

TEST(SpatialForces, ConicalPendulumRodTension) {
  const spec::AnalysisReport r = AnalyzeScene(Load(kConicalPendulum));
  ASSERT_TRUE(r.ok());
  const double l = 0.8, theta = 0.6, omega = std::sqrt(9.81 / (l * std::cos(theta)));
  const double tension = 1.5 * 9.81 / std::cos(theta);
  double worst_force = 0, worst_moment = 0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double a = omega * r.times_s[i];
    worst_force = std::max({worst_force, std::abs(Series(r, "fx")[i] - tension * std::sin(theta) * std::cos(a)),
                            std::abs(Series(r, "fy")[i] - tension * std::sin(theta) * std::sin(a)),
                            std::abs(Series(r, "fz")[i] - tension * std::cos(theta))});
    worst_moment = std::max(
        {worst_moment, std::abs(Series(r, "mx")[i]), std::abs(Series(r, "my")[i]), std::abs(Series(r, "mz")[i])});
  }
  EXPECT_LT(worst_force, 1e-6 * tension);
  EXPECT_LT(worst_moment, 1e-6 * tension * l);
  std::cout << "conical pendulum: rod tension " << tension << " N, largest error of the reaction " << worst_force
            << " N, of its moment " << worst_moment << " N m\n";
}

// A 1 kg block on a vertical prismatic joint hanging from a spring (k =
// 100 N/m, L0 = 0.4 m, c = 0.5 N s/m), released 0.6 m below the anchor;
// `SPRING` is replaced by the spring's law.
constexpr char kHangingBlock[] = R"pb(
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
    springs { name: "spring" a: "ground.anchor" b: "block.centre" free_length_m { value: 0.4 } SPRING }
    gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
  }
  outputs { name: "length" spring_length { spring: "spring" } }
  outputs { name: "force" spring_force { spring: "spring" } }
  outputs { name: "kinetic" kinetic_energy {} }
  outputs { name: "potential" potential_energy {} }
  time_grid { start_s: 0 end_s: 2 points: 21 }
  integrator { relative_tolerance: 1e-10 absolute_tolerance: 1e-10 }
)pb";

std::string HangingBlock(const std::string& spring) {
  std::string text = kHangingBlock;
  text.replace(text.find("SPRING"), 6, spring);
  return text;
}

TEST(SpatialForces, LinearTabulatedSpringEqualsTheLinearOne) {
  const spec::AnalysisReport linear =
      AnalyzeScene(Load(HangingBlock("stiffness_n_per_m { value: 100 } damping_n_s_per_m { value: 0.5 }")));
  const spec::AnalysisReport tabulated = AnalyzeScene(Load(HangingBlock(
      "deflection_curve { x: [-1, 0, 0.5] force_n: [-100, 0, 50] } velocity_curve { x: [-5, 5] force_n: [-2.5, "
      "2.5] }")));
  ASSERT_TRUE(linear.ok() && tabulated.ok());
  double worst_length = 0, worst_force = 0;
  for (size_t i = 0; i < linear.times_s.size(); ++i) {
    worst_length = std::max(worst_length, std::abs(Series(linear, "length")[i] - Series(tabulated, "length")[i]));
    worst_force = std::max(worst_force, std::abs(Series(linear, "force")[i] - Series(tabulated, "force")[i]));
  }
  EXPECT_LT(worst_length, 1e-9);
  EXPECT_LT(worst_force, 1e-7);
  // The strain energy of the curve is that of the linear spring.
  EXPECT_NEAR(Series(tabulated, "potential")[0], Series(linear, "potential")[0], 1e-12);
  // Strain k (0.2 m)^2 / 2, gravity m g z with z = -0.6 m.
  EXPECT_NEAR(Series(linear, "potential")[0], 0.5 * 100 * 0.2 * 0.2 - 9.81 * 0.6, 1e-9);
  // The block moves: the comparison is not between two resting blocks.
  EXPECT_GT(std::abs(Series(linear, "length")[5] - 0.6), 0.01);
  // An actuator force adds to the tension: at rest at the start, the
  // spring force is k (L - L0) + F.
  const spec::AnalysisReport actuated = AnalyzeScene(Load(HangingBlock(
      "stiffness_n_per_m { value: 100 } actuator_force_n { value: 7 }")));
  ASSERT_TRUE(actuated.ok());
  EXPECT_NEAR(Series(actuated, "force")[0], 100 * 0.2 + 7, 1e-9);
}

TEST(SpatialForces, LeavingASpringTableFailsNamingTheSpring) {
  // The block swings from a deflection of 0.2 m up to about -0.004 m: a
  // table from 0 ends the analysis where the deflection crosses 0.
  const spec::Scene scene =
      Load(HangingBlock("deflection_curve { x: [0, 0.3] force_n: [0, 30] }"));
  const spec::AnalysisReport r = engine::Analyze(scene, scene.DefaultParameterValues());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kModelValidity);
  EXPECT_NE(r.failure.reason.find("spring 'spring' left the range of its force table"), std::string::npos)
      << r.failure.reason;
  EXPECT_NE(r.failure.reason.find("the lower end of the table (0..0.3 m)"), std::string::npos) << r.failure.reason;
}

// Every loading error of the new elements names the file, the field's path
// and what was expected.
TEST(SpatialForces, LoadingErrorsNameTheFieldAndExpectation) {
  auto expect_error = [](std::string text, const std::string& from, const std::string& to, const std::string& want) {
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    const std::string error = LoadError(text);
    EXPECT_NE(error.find("forces.scene.textproto:"), std::string::npos) << error;
    EXPECT_NE(error.find(want), std::string::npos) << error << "\nexpected: " << want;
  };
  expect_error(kFreeBlock, "body: \"block\" torque_n_m", "body: \"blok\" torque_n_m",
               "spatial.torques[0].body: unknown body \"blok\" (bodies: block)");
  expect_error(kFreeBlock, "at: \"block.centre\" force_n { x", "at: \"block.center\" force_n { x",
               "spatial.point_forces[0].at: \"block\" has no marker \"center\" (markers: centre)");
  expect_error(kFreeBlock, "force_n { x { param: \"push\" } }", "",
               "spatial.point_forces[0].force_n: missing: expected e.g.");
  expect_error(kFreeBlock, "name: \"shake\"", "name: \"push\"", "spatial.point_forces[1].name");
  expect_error(kFreeBlock, "values: [0, 2]", "values: [0, 2, 3]",
               "spatial.torques[0].tabulated.times_s: a table needs at least 2 points and as many times_s as values");
  expect_error(kFreeBlock, "times_s: [0, 2]", "times_s: [0, 1]",
               "spatial.torques[0].tabulated.times_s: the table covers 0..1 s; it must cover the motion");
  expect_error(kTorsionalPendulum, "SPATIAL_JOINT_REVOLUTE", "SPATIAL_JOINT_SPHERICAL",
               "spatial.rotational_springs[0].joint: joint \"hinge\" is not revolute or cylindrical");
  expect_error(kTorsionalPendulum, "stiffness_n_m_per_rad { value: 4 }", "stiffness_n_m_per_rad { value: -4 }",
               "spatial.rotational_springs[0].stiffness_n_m_per_rad");
  expect_error(kTorsionalPendulum, "spring: \"torsion\"", "spring: \"torsoin\"",
               "outputs[2].rotational_spring_torque.spring: unknown rotational spring \"torsoin\" (rotational "
               "springs: torsion)");
  expect_error(kBushingMount, "b: \"block.mount\"", "b: \"ground.mount\"",
               "spatial.bushings[0].b: a bushing joins two different bodies");
  expect_error(kBushingMount, "y { value: 800 }", "y { value: -800 }", "spatial.bushings[0].stiffness_n_per_m.y");
  expect_error(kBushingMount, "bushing_force { bushing: \"mount\" axis: AXIS_X }",
               "bushing_force { bushing: \"mnt\" axis: AXIS_X }",
               "outputs[4].bushing_force.bushing: unknown bushing \"mnt\" (bushings: mount)");
  expect_error(kBushingMount, "bushing_force { bushing: \"mount\" axis: AXIS_X }", "bushing_force { bushing: \"mount\" }",
               "outputs[4].bushing_force.axis: expected AXIS_X, AXIS_Y or AXIS_Z");
  expect_error(HangingBlock("deflection_curve { x: [0, 0.3, 0.2] force_n: [0, 30, 20] }"), "", "",
               "spatial.springs[0].deflection_curve.x: must increase strictly: 0.2 after 0.3 (point 2)");
  expect_error(kOffsetCrank, "drivers { joint: \"motor\" constant_rate { rate { value: 3 } } }", "",
               "outputs[0].driver_effort.joint: joint \"motor\" has no driver: a driver effort needs one");
}

TEST(SpatialForces, SpatialForceOutputsAreRefusedInPlanarScenes) {
  const std::string error = LoadError(R"pb(
    multibody {
      bodies { name: "b" mass_kg { value: 1 } inertia_kg_m2 { value: 1 } markers { name: "m" } }
    }
    outputs { name: "w" body_angular_velocity { body: "b" axis: AXIS_Z } }
    time_grid { end_s: 1 points: 2 }
  )pb");
  EXPECT_NE(error.find("output \"w\" needs a spatial model; this scene's model is multibody"), std::string::npos)
      << error;
}

}  // namespace
}  // namespace mbopt::spatial
