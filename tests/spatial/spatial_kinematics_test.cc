// Kinematic analysis of fully driven spatial scenes (every degree of freedom
// driven) from their text: an RSUR four-bar's output angle against its
// closed-form input-output relation and its velocities and accelerations
// against differences of its positions; drivers of a prismatic joint's and
// a cylindrical joint's slide; driver efforts by inverse dynamics against
// Newton's second law; and the loading errors of slide drivers.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "absl/strings/str_format.h"
#include "spec/io/study_io.h"
#include "tests/spatial/scene_text_testing.h"
#include "spec/layout.h"
#include "spec/responses.h"
#include "worker/engine/analysis.h"

namespace mbopt::spatial {
namespace {

using Eigen::Vector3d;

constexpr double kPi = std::numbers::pi;

using scene_text::Series;

constexpr char kFileLabel[] = "kinematic.scene.textproto";
spec::Scene Load(const std::string& text) { return scene_text::Load(text, kFileLabel); }
std::string LoadError(const std::string& text) { return scene_text::LoadError(text, kFileLabel); }

std::string Vec(const Vector3d& v) {
  return absl::StrFormat("{ x { value: %.17g } y { value: %.17g } z { value: %.17g } }", v.x(), v.y(), v.z());
}

// An RSUR spatial four-bar: a crank of radius r1 turning about world z at
// the origin (driven at one turn per second), a coupler of length L, a
// rocker of radius r2 turning about world x at D. The crank's end is
// B = (r1 cos t, r1 sin t, 0); the rocker's end C turns about x from C0.
// With e = B - D and C0 - D = (0, cy, cz), |B - C|^2 = L^2 reads
//   P cos(psi) + Q sin(psi) = R,
//   P = ey cy + ez cz, Q = ez cy - ey cz, R = (|e|^2 + r2^2 - L^2) / 2,
// so psi = atan2(Q, P) -+ acos(R / hypot(P, Q)), the branch the rocker
// starts on. The coupler's spin about its own axis is held by a universal
// joint at C (its cross: the rocker's axis and a normal of the coupler).
struct Rsur {
  // A crank short enough to turn fully: |R| / hypot(P, Q) stays below 0.65.
  const double r1 = 0.04;
  const Vector3d d = Vector3d(0.25, 0.05, 0.12);
  const Vector3d c0 = Vector3d(0.25, 0.05 + 0.15, 0.12);  // r2 = 0.15
  Vector3d B(double theta) const { return Vector3d(r1 * std::cos(theta), r1 * std::sin(theta), 0.0); }
  double L() const { return (c0 - B(0.0)).norm(); }
  // Both solutions of the relation at crank angle theta.
  std::pair<double, double> Psi(double theta) const {
    const Vector3d e = B(theta) - d, c = c0 - d;
    const double p = e.y() * c.y() + e.z() * c.z(), q = e.z() * c.y() - e.y() * c.z();
    const double r = 0.5 * (e.squaredNorm() + c.squaredNorm() - L() * L());
    const double base = std::atan2(q, p), spread = std::acos(r / std::hypot(p, q));
    return {base - spread, base + spread};
  }
  std::string Scene(int points) const {
    const Vector3d b0 = B(0.0), mid = 0.5 * (b0 + c0), u = (c0 - b0).normalized();
    // The coupler's marker at C: x along the coupler, y normal to it and to
    // the rocker's axis (world x), so the cross's arms are perpendicular.
    Eigen::Matrix3d axes;
    axes.col(0) = u;
    axes.col(1) = u.cross(Vector3d::UnitX()).normalized();
    axes.col(2) = axes.col(0).cross(axes.col(1));
    const Eigen::AngleAxisd coupler_end(axes);
    return absl::StrFormat(R"pb(
      spatial {
        ground_markers { name: "crank_axis" }
        ground_markers { name: "rocker_axis" position_m %s orientation { axis_angle { axis { y { value: 1 } } angle_deg: 90 } } }
        bodies {
          name: "crank" mass_kg { value: 0.5 }
          principal_inertia { moments_kg_m2 { x { value: 1e-4 } y { value: 4e-4 } z { value: 4e-4 } } }
          position_m { x { value: %.17g } }
          markers { name: "hub" position_m { x { value: %.17g } } }
          markers { name: "end" position_m { x { value: %.17g } } }
        }
        bodies {
          name: "coupler" mass_kg { value: 0.8 }
          principal_inertia { moments_kg_m2 { x { value: 1e-4 } y { value: 3e-3 } z { value: 3e-3 } } }
          position_m %s
          markers { name: "b" position_m %s }
          markers {
            name: "c" position_m %s
            orientation { axis_angle { axis %s angle_deg: %.17g } }
          }
        }
        bodies {
          name: "rocker" mass_kg { value: 0.6 }
          principal_inertia { moments_kg_m2 { x { value: 2e-3 } y { value: 1e-3 } z { value: 1e-3 } } }
          position_m %s
          markers { name: "hub" orientation { axis_angle { axis { y { value: 1 } } angle_deg: 90 } } }
          markers { name: "end" position_m %s }
        }
        joints { name: "input" kind: SPATIAL_JOINT_REVOLUTE a: "ground.crank_axis" b: "crank.hub" }
        joints { name: "ball" kind: SPATIAL_JOINT_SPHERICAL a: "crank.end" b: "coupler.b" }
        joints { name: "cross" kind: SPATIAL_JOINT_UNIVERSAL a: "rocker.end" b: "coupler.c" }
        joints { name: "output" kind: SPATIAL_JOINT_REVOLUTE a: "ground.rocker_axis" b: "rocker.hub" }
        drivers { joint: "input" constant_rate { rate { value: %.17g } } }
        gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
      }
      outputs { name: "psi" joint_coordinate { joint: "output" } }
      outputs { name: "psi_rate" joint_rate { joint: "output" } }
      outputs { name: "cy" marker_position { marker: "rocker.end" axis: AXIS_Y } }
      outputs { name: "cz" marker_position { marker: "rocker.end" axis: AXIS_Z } }
      outputs { name: "vy" marker_velocity { marker: "rocker.end" axis: AXIS_Y } }
      outputs { name: "vz" marker_velocity { marker: "rocker.end" axis: AXIS_Z } }
      outputs { name: "ay" marker_acceleration { marker: "rocker.end" axis: AXIS_Y } }
      outputs { name: "az" marker_acceleration { marker: "rocker.end" axis: AXIS_Z } }
      outputs { name: "torque" driver_effort { joint: "input" } }
      time_grid { start_s: 0 end_s: 1 points: %d }
    )pb",
                           Vec(d), r1 / 2, -r1 / 2, r1 / 2, Vec(mid), Vec(b0 - mid), Vec(c0 - mid),
                           Vec(coupler_end.axis()), coupler_end.angle() * 180 / kPi, Vec(d), Vec(c0 - d), 2 * kPi,
                           points);
  }
};

TEST(SpatialKinematics, RsurOutputAngleFollowsTheClosedForm) {
  const Rsur rsur;
  const spec::Scene scene = Load(rsur.Scene(401));
  const spec::AnalysisReport r = engine::Analyze(scene, scene.DefaultParameterValues());
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  EXPECT_EQ(r.formulation, spec::Formulation::kKinematic);
  EXPECT_EQ(r.counters.rhs_evaluations, 0);
  // The rocker starts at psi = 0: one of the two solutions at theta = 0.
  const auto [first, second] = rsur.Psi(0.0);
  const bool minus_branch = std::abs(first) < std::abs(second);
  ASSERT_LT(std::min(std::abs(first), std::abs(second)), 1e-12);
  double worst = 0.0, range_min = 0.0, range_max = 0.0;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const auto [minus, plus] = rsur.Psi(2 * kPi * r.times_s[i]);
    const double psi = minus_branch ? minus : plus;
    worst = std::max(worst, std::abs(std::remainder(Series(r, "psi")[i] - psi, 2 * kPi)));
    range_min = std::min(range_min, Series(r, "psi")[i]);
    range_max = std::max(range_max, Series(r, "psi")[i]);
  }
  EXPECT_LT(worst, 1e-10);
  // The rocker does swing (the test is not of a mechanism standing still).
  EXPECT_GT(range_max - range_min, 0.3);
  std::cout << "RSUR: output angle within " << worst << " rad of the closed form over a swing of "
            << range_max - range_min << " rad; " << r.counters.time_steps << " position solves, "
            << r.counters.newton_iterations << " Newton iterations\n";
}

// Velocities and accelerations from the velocity and acceleration equations
// against central differences of the positions (h = 2.5 ms: the
// differences' own error is some 1e-5 of the values).
TEST(SpatialKinematics, RsurRatesMatchDifferencesOfPositions) {
  const Rsur rsur;
  const spec::Scene scene = Load(rsur.Scene(401));
  const spec::AnalysisReport r = engine::Analyze(scene, scene.DefaultParameterValues());
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  const double h = r.times_s[1] - r.times_s[0];
  double worst_v = 0, worst_a = 0, worst_rate = 0, largest_a = 0;
  for (size_t i = 1; i + 1 < r.times_s.size(); ++i) {
    for (const auto& [x, v, a] : {std::tuple{"cy", "vy", "ay"}, std::tuple{"cz", "vz", "az"}}) {
      const std::vector<double>& p = Series(r, x);
      worst_v = std::max(worst_v, std::abs((p[i + 1] - p[i - 1]) / (2 * h) - Series(r, v)[i]));
      worst_a = std::max(worst_a, std::abs((p[i + 1] - 2 * p[i] + p[i - 1]) / (h * h) - Series(r, a)[i]));
      largest_a = std::max(largest_a, std::abs(Series(r, a)[i]));
    }
    const std::vector<double>& psi = Series(r, "psi");
    worst_rate = std::max(worst_rate, std::abs((psi[i + 1] - psi[i - 1]) / (2 * h) - Series(r, "psi_rate")[i]));
  }
  EXPECT_GT(largest_a, 1.0);
  EXPECT_LT(worst_v, 1e-4);
  EXPECT_LT(worst_rate, 1e-3);
  EXPECT_LT(worst_a, 2e-3);
  std::cout << "RSUR: velocity vs differences " << worst_v << " m/s, rate " << worst_rate
            << " rad/s, acceleration " << worst_a << " m/s^2 (largest " << largest_a << ")\n";
}

// The crank's driving torque balances the power the mechanism takes: with
// no friction, torque * omega = d(kinetic + potential)/dt, the energy
// differenced over the grid.
TEST(SpatialKinematics, RsurDriverTorqueSuppliesTheMechanismsPower) {
  const Rsur rsur;
  std::string text = rsur.Scene(401);
  text.insert(text.find("      time_grid"),
              "outputs { name: \"kinetic\" kinetic_energy {} }\n"
              "outputs { name: \"potential\" potential_energy {} }\n");
  const spec::Scene scene = Load(text);
  const spec::AnalysisReport r = engine::Analyze(scene, scene.DefaultParameterValues());
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  const double h = r.times_s[1] - r.times_s[0], omega = 2 * kPi;
  double worst = 0, largest = 0;
  for (size_t i = 1; i + 1 < r.times_s.size(); ++i) {
    const double e_plus = Series(r, "kinetic")[i + 1] + Series(r, "potential")[i + 1];
    const double e_minus = Series(r, "kinetic")[i - 1] + Series(r, "potential")[i - 1];
    const double power = Series(r, "torque")[i] * omega;
    worst = std::max(worst, std::abs((e_plus - e_minus) / (2 * h) - power));
    largest = std::max(largest, std::abs(power));
  }
  EXPECT_GT(largest, 0.1);
  EXPECT_LT(worst, 1e-3 * largest);
  std::cout << "RSUR: driver power vs energy rate within " << worst << " W (largest " << largest << " W)\n";
}

// A 2 kg block on a vertical prismatic joint, its slide driven harmonically
// s = 0.05 sin(4 t) under gravity: the driver's force is m (s'' + g).
constexpr char kDrivenBlock[] = R"pb(
  parameters { name: "stroke" value: 50 unit: "mm" }
  spatial {
    ground_markers { name: "guide" }
    bodies {
      name: "block" mass_kg { value: 2 }
      principal_inertia { moments_kg_m2 { x { value: 0.01 } y { value: 0.01 } z { value: 0.01 } } }
      markers { name: "centre" }
    }
    joints { name: "slide" kind: SPATIAL_JOINT_PRISMATIC a: "ground.guide" b: "block.centre" }
    drivers {
      joint: "slide"
      harmonic { amplitude { param: "stroke" } angular_frequency_rad_per_s { value: 4 } }
    }
    gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
  }
  outputs { name: "z" marker_position { marker: "block.centre" axis: AXIS_Z } }
  outputs { name: "slide" joint_slide { joint: "slide" } }
  outputs { name: "force" driver_effort { joint: "slide" } }
  time_grid { start_s: 0 end_s: 2 points: 41 }
)pb";

TEST(SpatialKinematics, PrismaticSlideDriverAndItsForce) {
  const spec::Scene scene = Load(kDrivenBlock);
  const spec::AnalysisReport r = engine::Analyze(scene, scene.DefaultParameterValues());
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  EXPECT_EQ(r.formulation, spec::Formulation::kKinematic);
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double t = r.times_s[i], s = 0.05 * std::sin(4 * t);
    EXPECT_NEAR(Series(r, "z")[i], s, 1e-12) << "t = " << t;
    EXPECT_NEAR(Series(r, "slide")[i], s, 1e-12) << "t = " << t;
    EXPECT_NEAR(Series(r, "force")[i], 2 * (-16 * s + 9.81), 1e-9) << "t = " << t;
  }
}

// A cylindrical joint with both coordinates driven: a disc on a vertical
// axis turning at theta = 0.5 t^2 and sliding as s = 0.1 t. Its torque is
// I_zz theta'' = 0.02 N m; the slide's force m g, the slide at constant rate.
constexpr char kScrewingDisc[] = R"pb(
  spatial {
    ground_markers { name: "axis" }
    bodies {
      name: "disc" mass_kg { value: 3 }
      principal_inertia { moments_kg_m2 { x { value: 0.01 } y { value: 0.01 } z { value: 0.02 } } }
      markers { name: "centre" }
      markers { name: "rim" position_m { x { value: 0.2 } } }
    }
    joints { name: "spindle" kind: SPATIAL_JOINT_CYLINDRICAL a: "ground.axis" b: "disc.centre" }
    drivers { joint: "spindle" polynomial { coefficients { value: 0 } coefficients { value: 0 } coefficients { value: 0.5 } } }
    drivers { joint: "spindle" slide: true constant_rate { rate { value: 0.1 } } }
    gravity { acceleration_m_per_s2 { z { value: -9.81 } } }
  }
  outputs { name: "rim_x" marker_position { marker: "disc.rim" axis: AXIS_X } }
  outputs { name: "rim_z" marker_position { marker: "disc.rim" axis: AXIS_Z } }
  outputs { name: "torque" driver_effort { joint: "spindle" } }
  time_grid { start_s: 0 end_s: 2 points: 21 }
)pb";

TEST(SpatialKinematics, CylindricalJointDrivenInAngleAndSlide) {
  const spec::Scene scene = Load(kScrewingDisc);
  const spec::AnalysisReport r = engine::Analyze(scene, scene.DefaultParameterValues());
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  EXPECT_EQ(r.formulation, spec::Formulation::kKinematic);
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double t = r.times_s[i];
    EXPECT_NEAR(Series(r, "rim_x")[i], 0.2 * std::cos(0.5 * t * t), 1e-12) << "t = " << t;
    EXPECT_NEAR(Series(r, "rim_z")[i], 0.1 * t, 1e-12) << "t = " << t;
    EXPECT_NEAR(Series(r, "torque")[i], 0.02, 1e-10) << "t = " << t;
  }
}

// examples/suspension: fully driven, so kinematic; the pad's slide runs
// from -80 to +80 mm and the tyre's contact point follows it; each
// wishbone keeps its ball joint at its length from its pivot axis (front
// view); the toe changes (the start's bump steer, which the study reduces).
TEST(SpatialKinematics, SuspensionExampleHoldsItsLinksAndFollowsTheTravel) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile("examples/suspension/suspension.scene.textproto");
  ASSERT_TRUE(scene.ok()) << scene.status();
  const spec::AnalysisReport r = engine::Analyze(*scene, scene->DefaultParameterValues());
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  EXPECT_EQ(r.formulation, spec::Formulation::kKinematic);
  ASSERT_EQ(r.times_s.size(), 33u);
  EXPECT_NEAR(Series(r, "wheel_travel").front(), -0.08, 1e-15);
  EXPECT_NEAR(Series(r, "wheel_travel").back(), 0.08, 1e-15);
  double worst_length = 0, toe_min = 1, toe_max = -1, roll_min = 1, roll_max = -1;
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    EXPECT_NEAR(Series(r, "contact_z")[i], Series(r, "wheel_travel")[i], 1e-12);
    const double lower = std::hypot(Series(r, "lower_ball_y")[i] - 0.30, Series(r, "lower_ball_z")[i] - 0.20);
    const double upper = std::hypot(Series(r, "upper_ball_y")[i] - 0.42, Series(r, "upper_ball_z")[i] - 0.50);
    worst_length = std::max({worst_length, std::abs(lower - std::hypot(0.42, 0.05)), std::abs(upper - 0.26)});
    toe_min = std::min(toe_min, Series(r, "toe")[i]);
    toe_max = std::max(toe_max, Series(r, "toe")[i]);
    roll_min = std::min(roll_min, Series(r, "roll")[i]);
    roll_max = std::max(roll_max, Series(r, "roll")[i]);
  }
  EXPECT_LT(worst_length, 1e-12);
  // At the design position the upright stands as written: no toe, no roll.
  EXPECT_NEAR(Series(r, "toe")[16], 0.0, 1e-10);
  EXPECT_NEAR(Series(r, "roll")[16], 0.0, 1e-10);
  EXPECT_GT(toe_max - toe_min, 1e-3);
  std::cout << "suspension: link lengths held to " << worst_length << " m; toe range (bump steer) "
            << (toe_max - toe_min) * 180 / kPi << " deg, roll range " << (roll_max - roll_min) * 180 / kPi
            << " deg; " << r.counters.time_steps << " position solves, " << r.counters.newton_iterations
            << " Newton iterations\n";
}

// examples/suspension's study: it loads, and its roll-centre responses
// reproduce the front-view construction by hand at the design position
// (t = 0.5 s): the wishbone lines through (0.30, 0.20)-(0.72, 0.15) and
// (0.42, 0.50)-(0.68, 0.50) m meet at IC = (-2.22, 0.50) m; the line from
// the contact point (0.80, 0) to IC crosses y = 0 at z = 0.4 / 3.02 m.
TEST(SpatialKinematics, SuspensionStudyComputesTheRollCentre) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("examples/suspension/suspension.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(*study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  const std::vector<double> parameters = study->scene.DefaultParameterValues();
  const spec::AnalysisReport r = engine::Analyze(study->scene, parameters);
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  std::vector<spec::Series> outputs, storage;
  for (const spec::OutputValues& o : r.outputs) outputs.push_back(o.series);
  std::vector<const spec::Series*> signals;
  for (const spec::Series& o : outputs) signals.push_back(&o);
  spec::AppendResponses(*study, *layout, parameters, &storage, &signals);
  ASSERT_EQ(signals.size(), outputs.size() + study->responses.size());
  ASSERT_EQ(study->responses.back().name, "roll_centre_z");
  const std::vector<double>& roll_centre = (*signals.back())[0];
  ASSERT_EQ(roll_centre.size(), 33u);
  EXPECT_NEAR(roll_centre[16], 0.4 / 3.02, 1e-10);
  // Camber is minus the roll.
  const std::vector<double>& camber = (*signals[outputs.size()])[0];
  EXPECT_EQ(study->responses.front().name, "camber");
  EXPECT_DOUBLE_EQ(camber[0], -Series(r, "roll")[0]);
  std::cout << "suspension study: roll centre " << roll_centre[16] * 1e3 << " mm at the design position, "
            << roll_centre.front() * 1e3 << " mm in rebound, " << roll_centre.back() * 1e3 << " mm in bump\n";
}

TEST(SpatialKinematics, SlideDriverLoadingErrors) {
  std::string text = kScrewingDisc;
  text.replace(text.find("SPATIAL_JOINT_CYLINDRICAL"), 25, "SPATIAL_JOINT_REVOLUTE");
  std::string error = LoadError(text);
  EXPECT_NE(error.find("kinematic.scene.textproto:"), std::string::npos) << error;
  EXPECT_NE(error.find("spatial.drivers[1].slide: joint \"spindle\" is revolute: it has no slide"), std::string::npos)
      << error;

  text = kScrewingDisc;
  text.replace(text.find("slide: true"), 11, "");
  error = LoadError(text);
  EXPECT_NE(error.find("spatial.drivers[1].joint: this joint's angle already has a driver"), std::string::npos)
      << error;

  text = kDrivenBlock;
  text.replace(text.find("driver_effort { joint: \"slide\" }"), 32, "driver_effort { joint: \"nothing\" }");
  error = LoadError(text);
  EXPECT_NE(error.find("outputs[2].driver_effort.joint: unknown joint \"nothing\""), std::string::npos) << error;
}

}  // namespace
}  // namespace mbopt::spatial
