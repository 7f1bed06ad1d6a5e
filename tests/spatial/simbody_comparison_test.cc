// mbopt's spatial kernel against Simbody (relative coordinates, its own
// integrator; the program mbopt_simbody_spatial_oracle) on the same
// mechanism: centres of mass and rotation matrices agree to 1e-6 over 2 s,
// released at rest and started spinning; and the closed loops of
// spatial_mechanisms.h (an RSSR four-bar, a driven Cardan shaft, Bricard's
// overconstrained linkage, integrated with independent combinations of its
// joint rows, and the ten-bar spherical chain of the speed benchmark);
// and the static equilibrium of a chain hung on springs against the rest
// Simbody's damped motion comes to; a body hung on a bushing turned far
// from its rest against Simbody's Force::LinearBushing.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/spatial/mechanism_model.h"
#include "tests/spatial/spatial_oracle.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/spatial/euler_parameters.h"
#include "worker/spatial/redundant_constraints.h"
#include "worker/spatial/spatial_assembly.h"
#include "worker/spatial/spatial_force_elements.h"
#include "worker/spatial/spatial_static_equilibrium.h"
#include "worker/spatial/spatial_system.h"

namespace mbopt::spatial {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using VectorXdRow = std::vector<double>;

// Simbody (Runge-Kutta-Merson) at accuracy 1e-12 over 2 s in 100 intervals
// unless told otherwise.
std::vector<std::vector<double>> RunSimbody(const std::string& mechanism, bool* ok,
                                            const std::string& accuracy_end_intervals = "1e-12 2 100") {
  std::vector<std::vector<double>> values;
  const std::string command =
      std::string(MBOPT_SIMBODY_SPATIAL_ORACLE) + " " + mechanism + " " + accuracy_end_intervals;
  FILE* pipe = popen(command.c_str(), "r");
  *ok = pipe != nullptr;
  if (pipe == nullptr) return values;
  char line[8192];
  while (std::fgets(line, sizeof line, pipe) != nullptr) {
    std::istringstream in(line);
    double t = 0.0, v = 0.0;
    in >> t;
    std::vector<double> row;
    while (in >> v) row.push_back(v);
    values.push_back(row);
  }
  *ok = pclose(pipe) == 0;
  return values;
}

Model DoublePendulum(const oracle::SpatialDoublePendulum& p, bool spinning) {
  Model m;
  const Vector3d w = spinning ? Vector3d(p.angular_velocity_rad_per_s[0], p.angular_velocity_rad_per_s[1],
                                         p.angular_velocity_rad_per_s[2])
                              : Vector3d::Zero();
  Vector3d joint = Vector3d::Zero();  // the body's inboard joint, world
  for (int i = 0; i < 2; ++i) {
    Body b;
    b.name = i == 0 ? "upper" : "lower";
    b.mass_kg = p.mass_kg[i];
    b.inertia_kg_m2 = Vector3d(p.inertia_kg_m2[i][0], p.inertia_kg_m2[i][1], p.inertia_kg_m2[i][2]).asDiagonal();
    b.orientation = AxisAngle(Vector3d(p.axis[i][0], p.axis[i][1], p.axis[i][2]), p.angle_rad[i]);
    b.position_m = joint + b.orientation * Vector3d(0, 0, -p.half_length_m[i]);
    b.angular_velocity_rad_per_s = w;
    b.velocity_m_per_s = w.cross(b.position_m);  // one rigid body turning about the shoulder
    joint = b.position_m + b.orientation * Vector3d(0, 0, -p.half_length_m[i]);
    m.bodies.push_back(b);
  }
  Frame ground, upper_top, upper_bottom, lower_top;
  upper_top.body = 0;
  upper_top.position_m = {0, 0, p.half_length_m[0]};
  upper_bottom.body = 0;
  upper_bottom.position_m = {0, 0, -p.half_length_m[0]};
  lower_top.body = 1;
  lower_top.position_m = {0, 0, p.half_length_m[1]};
  m.joints.push_back({"shoulder", Joint::Kind::kSpherical, ground, upper_top});
  m.joints.push_back({"elbow", Joint::Kind::kSpherical, upper_bottom, lower_top});
  m.gravity_m_per_s2 = Vector3d(0, 0, -p.g);
  return m;
}

// The largest difference of mbopt's values to Simbody's over 2 s.
double Compare(bool spinning, double tolerance) {
  const oracle::SpatialDoublePendulum p;
  bool ok = false;
  const std::vector<std::vector<double>> simbody =
      RunSimbody(spinning ? "spinning_double_pendulum" : "double_pendulum", &ok);
  EXPECT_TRUE(ok) << "the Simbody oracle failed";
  const Model model = DoublePendulum(p, spinning);
  EXPECT_TRUE(model.Validate().ok());
  const SpatialSystem s(model);
  const SpatialAssembly assembled = AssembleSpatial(s, 0.0);
  EXPECT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  // The initial velocities are consistent: assembly keeps them.
  EXPECT_LT((assembled.v - s.InitialVelocityGuess()).cwiseAbs().maxCoeff(), 1e-14);
  std::vector<double> times;
  for (int i = 0; i <= 100; ++i) times.push_back(0.02 * i);
  multibody::ForwardDynamicsOptions options;
  options.relative_tolerance = tolerance;
  options.absolute_tolerance = tolerance;
  multibody::ForwardDynamicsCounters counters;
  std::vector<std::vector<double>> ours;
  const spec::AnalysisFailure f = multibody::IntegrateForward(
      s, 0.0, assembled.q, assembled.v, times, options,
      [&](const multibody::MotionSample& sample) {
        std::vector<double> row;
        for (int b = 0; b < 2; ++b) {
          for (int k = 0; k < 3; ++k) row.push_back(sample.q[7 * b + k]);
        }
        for (int b = 0; b < 2; ++b) {
          const Matrix3d r = s.BodyRotation(b, sample.q);
          for (int i = 0; i < 3; ++i) {
            for (int k = 0; k < 3; ++k) row.push_back(r(i, k));
          }
        }
        ours.push_back(row);
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  EXPECT_TRUE(f.ok()) << f.reason;
  EXPECT_EQ(simbody.size(), ours.size());
  double worst = 0.0, swing = 0.0;
  for (size_t i = 0; i < std::min(ours.size(), simbody.size()); ++i) {
    EXPECT_EQ(simbody[i].size(), ours[i].size());
    for (size_t k = 0; k < std::min(ours[i].size(), simbody[i].size()); ++k) {
      worst = std::max(worst, std::abs(ours[i][k] - simbody[i][k]));
      swing = std::max(swing, std::abs(ours[i][k] - ours[0][k]));
    }
  }
  EXPECT_GT(swing, 0.5);  // the pendulum moves: metres and rotation entries of order 1
  std::cout << (spinning ? "spinning" : "released") << " spatial double pendulum at tolerance " << tolerance
            << ": largest difference to Simbody " << worst << " over 2 s, " << counters.steps << " steps\n";
  return worst;
}

// At tolerance 1e-10, as the planar comparison (tests/oracle): measured
// 1.1e-8 with the Newton matrix by difference quotients, 1.3e-8 analytic.
TEST(SpatialSimbodyComparison, DoublePendulumReleasedAtRest) {
  EXPECT_LT(Compare(false, 1e-10), 1e-6);  // m, and rotation matrix entries
}

// At 1e-10 too: measured 8.9e-8 (difference quotients), 8.2e-8 (analytic).
TEST(SpatialSimbodyComparison, DoublePendulumStartedSpinning) { EXPECT_LT(Compare(true, 1e-10), 1e-6); }

struct LoopComparison {
  double worst = 0.0;  // largest difference to Simbody (m, rotation entries)
  double swing = 0.0;  // largest change of a value from its start
  int redundant_rows = 0;
  std::vector<VectorXdRow> ours;
};

// A closed loop of spatial_mechanisms.h by both codes, 2 s at 100
// intervals, every body's centre of mass and rotation matrix; ours with
// IntegrateWithRedundantRows when a row is redundant.
LoopComparison CompareLoop(const std::string& name, const oracle::Mechanism& mechanism, double tolerance,
                           multibody::ForwardDynamicsOptions::Method method =
                               multibody::ForwardDynamicsOptions::Method::kImplicitBdf) {
  LoopComparison out;
  bool ok = false;
  const std::vector<std::vector<double>> simbody = RunSimbody(name, &ok);
  EXPECT_TRUE(ok) << "the Simbody oracle failed on " << name;
  const Model model = ModelOf(mechanism);
  EXPECT_TRUE(model.Validate().ok()) << model.Validate().message();
  const SpatialSystem s(model);
  const SpatialAssembly assembled = AssembleSpatial(s, 0.0);
  EXPECT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  out.redundant_rows = assembled.redundant_rows;
  std::vector<double> times;
  for (int i = 0; i <= 100; ++i) times.push_back(0.02 * i);
  multibody::ForwardDynamicsOptions options;
  options.relative_tolerance = tolerance;
  options.absolute_tolerance = tolerance;
  options.method = method;
  multibody::ForwardDynamicsCounters counters;
  const int bodies = static_cast<int>(model.bodies.size());
  RedundantIntegrationCounters redundant;
  const multibody::MotionCallback record = [&](const multibody::MotionSample& sample) {
    VectorXdRow row;
    for (int b = 0; b < bodies; ++b) {
      for (int k = 0; k < 3; ++k) row.push_back(sample.q[7 * b + k]);
      const Matrix3d r = s.BodyRotation(b, sample.q);
      for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 3; ++k) row.push_back(r(i, k));
      }
    }
    out.ours.push_back(row);
    return spec::AnalysisFailure::Ok();
  };
  const spec::AnalysisFailure f =
      out.redundant_rows > 0
          ? IntegrateWithRedundantRows(s, assembled.independent_combination, 0.0, assembled.q, assembled.v, times,
                                       options, record, &counters, &redundant)
          : multibody::IntegrateForward(s, 0.0, assembled.q, assembled.v, times, options, record, &counters);
  EXPECT_TRUE(f.ok()) << f.reason;
  EXPECT_EQ(simbody.size(), out.ours.size());
  for (size_t i = 0; i < std::min(out.ours.size(), simbody.size()); ++i) {
    EXPECT_EQ(simbody[i].size(), out.ours[i].size());
    for (size_t k = 0; k < std::min(out.ours[i].size(), simbody[i].size()); ++k) {
      out.worst = std::max(out.worst, std::abs(out.ours[i][k] - simbody[i][k]));
      out.swing = std::max(out.swing, std::abs(out.ours[i][k] - out.ours[0][k]));
    }
  }
  std::cout << name << (method == multibody::ForwardDynamicsOptions::Method::kExplicitRungeKutta ? " (explicit)" : "")
            << " at tolerance " << tolerance << ": largest difference to Simbody " << out.worst
            << " over 2 s, " << counters.steps << " steps, " << out.redundant_rows << " redundant row(s)\n";
  return out;
}

// The aim, as for the double pendulum. Measured at tolerance 1e-10
// with the analytic Newton matrix: RSSR 2.8e-7, Cardan shaft 3.6e-11,
// Bricard 6.4e-9, the spherical chain 2.5e-8 (by difference quotients:
// 1.5e-7, 6.9e-11, 3.3e-9).
constexpr double kLoopAgreement = 1e-6;  // m, and rotation matrix entries

TEST(SpatialSimbodyComparison, RssrFourBarFallingFromRest) {
  const LoopComparison c = CompareLoop("rssr", oracle::Rssr(), 1e-10);
  EXPECT_EQ(c.redundant_rows, 0);
  EXPECT_GT(c.swing, 0.3);  // the crank swings through a good part of a turn
  EXPECT_LT(c.worst, kLoopAgreement);
}

// The driven shaft (its speed ratio against the closed form:
// SpatialDynamics.UniversalJointOutputSpeedFluctuates).
TEST(SpatialSimbodyComparison, CardanShaftDriven) {
  const oracle::Mechanism mechanism = oracle::CardanShaft();
  const LoopComparison c = CompareLoop("cardan", mechanism, 1e-10);
  EXPECT_EQ(c.redundant_rows, 0);
  EXPECT_GT(c.swing, 1.0);  // rotation entries run through -1 .. 1
  EXPECT_LT(c.worst, kLoopAgreement);
}

// Bricard's linkage: 0 degrees of freedom by counting, 1 in fact; its
// joint rows are integrated as independent combinations.
TEST(SpatialSimbodyComparison, BricardLinkageFallingFromRest) {
  const LoopComparison c = CompareLoop("bricard", oracle::Bricard(), 1e-10);
  EXPECT_EQ(c.redundant_rows, 1);
  EXPECT_GT(c.swing, 0.5);
  EXPECT_LT(c.worst, kLoopAgreement);
}

// The chain of spatial_oracle.h as an mbopt model: revolute joints whose
// frames turn world z onto the hinge axes.
Model HungChain(const oracle::SpatialHungChain& p) {
  Model m;
  for (int i = 0; i < 2; ++i) {
    Body b;
    b.name = i == 0 ? "upper" : "lower";
    b.mass_kg = p.mass_kg[i];
    b.inertia_kg_m2 = Vector3d(p.inertia_kg_m2[i][0], p.inertia_kg_m2[i][1], p.inertia_kg_m2[i][2]).asDiagonal();
    b.position_m = {0, 0, i == 0 ? -p.half_length_m[0] : -2 * p.half_length_m[0] - p.half_length_m[1]};
    m.bodies.push_back(b);
  }
  const Matrix3d about_x = AxisAngle(Vector3d::UnitY(), std::numbers::pi / 2);
  const Matrix3d about_y = AxisAngle(Vector3d::UnitX(), -std::numbers::pi / 2);
  m.joints.push_back({"shoulder", Joint::Kind::kRevolute, Frame{kGround, Vector3d::Zero(), about_x},
                      Frame{0, Vector3d(0, 0, p.half_length_m[0]), about_x}});
  m.joints.push_back({"elbow", Joint::Kind::kRevolute, Frame{0, Vector3d(0, 0, -p.half_length_m[0]), about_y},
                      Frame{1, Vector3d(0, 0, p.half_length_m[1]), about_y}});
  for (int i = 0; i < 2; ++i) {
    SpringDamper spring;
    spring.name = i == 0 ? "upper_spring" : "lower_spring";
    spring.a = Point{kGround, Vector3d(p.anchor_m[i][0], p.anchor_m[i][1], p.anchor_m[i][2])};
    spring.b = Point{i, Vector3d(p.attachment_m[i][0], p.attachment_m[i][1], p.attachment_m[i][2])};
    spring.stiffness_n_per_m = p.stiffness_n_per_m[i];
    spring.free_length_m = p.free_length_m[i];
    m.springs.push_back(spring);
  }
  m.gravity_m_per_s2 = Vector3d(0, 0, -p.g);
  return m;
}

// Simbody's damped chain after 40 s (accuracy 1e-12) against mbopt's static
// equilibrium from the same start: centres of mass (m) and rotation matrix
// entries agree to 1e-8.
TEST(SpatialSimbodyComparison, ChainHungOnSpringsComesToTheStaticEquilibrium) {
  const oracle::SpatialHungChain p;
  bool ok = false;
  const std::vector<std::vector<double>> simbody = RunSimbody("hung_chain", &ok, "1e-12 40 2");
  ASSERT_TRUE(ok) << "the Simbody oracle failed";
  ASSERT_EQ(simbody.size(), 3u);
  const Model model = HungChain(p);
  ASSERT_TRUE(model.Validate().ok()) << model.Validate();
  const SpatialSystem s(model);
  const SpatialAssembly assembled = AssembleSpatial(s, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  ASSERT_EQ(assembled.degrees_of_freedom, 2);
  std::vector<double> ours;
  multibody::StaticCounters counters;
  const spec::AnalysisFailure f = RunSpatialStaticEquilibrium(
      s, assembled, {0.0}, nullptr,
      [&](const multibody::MotionSample& sample) {
        for (int b = 0; b < 2; ++b) {
          for (int k = 0; k < 3; ++k) ours.push_back(sample.q[7 * b + k]);
        }
        for (int b = 0; b < 2; ++b) {
          const Matrix3d r = s.BodyRotation(b, sample.q);
          for (int i = 0; i < 3; ++i) {
            for (int k = 0; k < 3; ++k) ours.push_back(r(i, k));
          }
        }
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  ASSERT_TRUE(f.ok()) << f.reason;
  const std::vector<double>& rest = simbody.back();
  const std::vector<double>& halfway = simbody[1];
  ASSERT_EQ(rest.size(), ours.size());
  double worst = 0.0, moved = 0.0, settled = 0.0;
  for (size_t k = 0; k < ours.size(); ++k) {
    worst = std::max(worst, std::abs(ours[k] - rest[k]));
    moved = std::max(moved, std::abs(rest[k] - simbody[0][k]));
    settled = std::max(settled, std::abs(rest[k] - halfway[k]));
  }
  // The springs swing the chain well away from hanging straight down, in
  // both hinges' planes.
  EXPECT_GT(moved, 0.1);
  EXPECT_LT(worst, 1e-8);
  std::cout << "chain hung on springs: largest difference of the static equilibrium to Simbody's rest after 40 s "
            << worst << " (moved " << moved << " from the start; Simbody's last 20 s moved it " << settled << "), "
            << counters.newton_iterations << " Newton iterations\n";
}

// The spatial speed benchmark's mechanism (bench/spatial): both codes
// must compute the same motion for its times to compare.
TEST(SpatialSimbodyComparison, SphericalChainFallingFromRest) {
  const LoopComparison c = CompareLoop("spherical_chain", oracle::SphericalChain(), 1e-10);
  EXPECT_EQ(c.redundant_rows, 0);
  EXPECT_GT(c.swing, 2.0);  // the arc falls metres below its ends
  EXPECT_LT(c.worst, kLoopAgreement);
}

// The explicit path (Verner 6(5) with projection onto the joints' rows and
// the Euler parameters' norm rows) to the same bound as IDAS: the
// benchmark's chain, a closed loop, and Bricard's redundant rows
// integrated as independent combinations.
constexpr auto kExplicit = multibody::ForwardDynamicsOptions::Method::kExplicitRungeKutta;

TEST(SpatialSimbodyComparison, ExplicitRungeKuttaSphericalChainFallingFromRest) {
  const LoopComparison c = CompareLoop("spherical_chain", oracle::SphericalChain(), 1e-10, kExplicit);
  EXPECT_EQ(c.redundant_rows, 0);
  EXPECT_GT(c.swing, 2.0);
  EXPECT_LT(c.worst, kLoopAgreement);
}

TEST(SpatialSimbodyComparison, ExplicitRungeKuttaRssrFourBarFallingFromRest) {
  const LoopComparison c = CompareLoop("rssr", oracle::Rssr(), 1e-10, kExplicit);
  EXPECT_EQ(c.redundant_rows, 0);
  EXPECT_GT(c.swing, 0.3);
  EXPECT_LT(c.worst, kLoopAgreement);
}

TEST(SpatialSimbodyComparison, ExplicitRungeKuttaBricardLinkageFallingFromRest) {
  const LoopComparison c = CompareLoop("bricard", oracle::Bricard(), 1e-10, kExplicit);
  EXPECT_EQ(c.redundant_rows, 1);
  EXPECT_GT(c.swing, 0.5);
  EXPECT_LT(c.worst, kLoopAgreement);
}

}  // namespace
}  // namespace mbopt::spatial

namespace mbopt::spatial {
namespace {

Vector3d V3(const double* v) { return Vector3d(v[0], v[1], v[2]); }

Model BushingBody(const oracle::SpatialBushingBody& p) {
  Model m;
  const Matrix3d ground_axes = AxisAngle(V3(p.ground_axis), p.ground_angle_rad);
  const Matrix3d turned = ground_axes * AxisAngle(V3(p.turn_axis), p.turn_angle_rad);
  Body b;
  b.name = "body";
  b.mass_kg = p.mass_kg;
  b.inertia_kg_m2 = V3(p.inertia_kg_m2).asDiagonal();
  b.orientation = turned;
  b.position_m = V3(p.ground_frame_m) + ground_axes * V3(p.displacement_m) - turned * V3(p.body_frame_m);
  b.velocity_m_per_s = V3(p.velocity_m_per_s);
  b.angular_velocity_rad_per_s = V3(p.angular_velocity_rad_per_s);
  m.bodies.push_back(b);
  Bushing bushing;
  bushing.name = "mount";
  bushing.a.position_m = V3(p.ground_frame_m);
  bushing.a.axes = ground_axes;
  bushing.b.body = 0;
  bushing.b.position_m = V3(p.body_frame_m);
  bushing.rotational_stiffness_n_m_per_rad = V3(p.stiffness);
  bushing.stiffness_n_per_m = V3(p.stiffness + 3);
  bushing.rotational_damping_n_m_s_per_rad = V3(p.damping);
  bushing.damping_n_s_per_m = V3(p.damping + 3);
  m.bushings.push_back(bushing);
  m.gravity_m_per_s2 = Vector3d(0, 0, -p.g);
  return m;
}

// Released turned by 63 deg about a skew axis, spinning at 2.7 rad/s,
// anisotropic stiffnesses, dampings and gravity: the bushing turns by up
// to 67 deg from its rest (its x-y-z angles reach 61, 25 and 55 deg),
// where a small-angle measure's moment (k sin(angle) about one axis)
// misses Simbody's by some 20 %. Measured at 1e-10: 4.1e-9 (m and
// rotation entries) over 2 s.
TEST(SpatialSimbodyComparison, BodyOnABushingTurnedFarFromRest) {
  const oracle::SpatialBushingBody p;
  bool ok = false;
  const std::vector<std::vector<double>> simbody = RunSimbody("bushing_body", &ok);
  ASSERT_TRUE(ok) << "the Simbody oracle failed";
  const Model model = BushingBody(p);
  ASSERT_TRUE(model.Validate().ok()) << model.Validate().message();
  const SpatialSystem s(model);
  const SpatialAssembly assembled = AssembleSpatial(s, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  std::vector<double> times;
  for (int i = 0; i <= 100; ++i) times.push_back(0.02 * i);
  multibody::ForwardDynamicsOptions options;
  options.relative_tolerance = 1e-10;
  options.absolute_tolerance = 1e-10;
  multibody::ForwardDynamicsCounters counters;
  std::vector<std::vector<double>> ours;
  Vector3d largest_angles = Vector3d::Zero();
  double largest_turn = 0.0;
  const spec::AnalysisFailure f = multibody::IntegrateForward(
      s, 0.0, assembled.q, assembled.v, times, options,
      [&](const multibody::MotionSample& sample) {
        std::vector<double> row(sample.q.data(), sample.q.data() + 3);
        const Matrix3d r = s.BodyRotation(0, sample.q);
        for (int i = 0; i < 3; ++i) {
          for (int k = 0; k < 3; ++k) row.push_back(r(i, k));
        }
        ours.push_back(row);
        largest_angles = largest_angles.cwiseMax(BushingLoadOf(model, 0, sample.q, sample.v).angles_rad.cwiseAbs());
        const Matrix3d relative = model.bushings[0].a.axes.transpose() * r;
        largest_turn = std::max(largest_turn, Eigen::AngleAxisd(relative).angle());
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  ASSERT_TRUE(f.ok()) << f.reason;
  ASSERT_EQ(simbody.size(), ours.size());
  double worst = 0.0;
  for (size_t i = 0; i < ours.size(); ++i) {
    ASSERT_EQ(simbody[i].size(), ours[i].size());
    for (size_t k = 0; k < ours[i].size(); ++k) worst = std::max(worst, std::abs(ours[i][k] - simbody[i][k]));
  }
  EXPECT_GT(largest_turn, 1.0);  // rad: far outside a small-angle measure's range
  EXPECT_LT(worst, 1e-6);
  std::cout << "body on a bushing: largest difference to Simbody " << worst << " over 2 s, " << counters.steps
            << " steps; largest x-y-z angles " << largest_angles.transpose() * 180 / std::numbers::pi
            << " deg, largest turn " << largest_turn * 180 / std::numbers::pi << " deg\n";
}

}  // namespace
}  // namespace mbopt::spatial
