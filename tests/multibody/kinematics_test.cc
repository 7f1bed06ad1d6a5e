// Assembly, degrees of freedom and kinematic analysis with inverse dynamics,
// against closed-form answers.
#include "worker/multibody/kinematic_analysis.h"

#include <cmath>
#include <cstdio>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/multibody/mechanisms.h"
#include "worker/multibody/assembly.h"

namespace mbopt::multibody {
namespace {

using ::testing::HasSubstr;
using testing::At;

// Newton closes the loops to 1e-11 m; velocities and accelerations are
// solved from the exact Jacobian: agreement with the closed form to 1e-9
// (relative to the motion's own scale) leaves room for round-off.
constexpr double kKinematicAgreement = 1e-9;

TEST(MultibodyKinematics, SliderCrankFollowsTheClosedForm) {
  constexpr double r = 0.3, l = 1.0, w = 2.0 * std::numbers::pi;
  const Model model = testing::SliderCrank(r, l, w);
  ASSERT_TRUE(model.Validate().ok()) << model.Validate();
  const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  EXPECT_EQ(assembled.degrees_of_freedom, 0);
  std::vector<double> times;
  for (int i = 0; i <= 200; ++i) times.push_back(0.005 * i);
  int checked = 0;
  KinematicCounters counters;
  const Point slider = At(2, 0.0);
  const spec::AnalysisFailure f = RunKinematics(
      m, assembled.q, times, KinematicOptions{}, [&](const MotionSample& s) {
        const double th = w * s.t_s, sn = std::sin(th), cs = std::cos(th);
        const double root = std::sqrt(l * l - r * r * sn * sn);
        const double x = r * cs + root;
        // d/dt of x, twice (th' = w).
        const double dx = -r * w * sn - r * r * w * sn * cs / root;
        const double ddx = -r * w * w * cs -
                           r * r * w * w * ((cs * cs - sn * sn) / root + r * r * sn * sn * cs * cs / (root * root * root));
        EXPECT_NEAR(m.PointPosition(slider, s.q).x(), x, kKinematicAgreement);
        EXPECT_NEAR(m.PointVelocity(slider, s.q, s.v).x(), dx, kKinematicAgreement * w);
        EXPECT_NEAR(m.PointAcceleration(slider, s.q, s.v, s.a).x(), ddx, kKinematicAgreement * w * w);
        EXPECT_NEAR(m.JointCoordinate(3, s.q), x, kKinematicAgreement);  // the slide's coordinate
        ++checked;
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  EXPECT_TRUE(f.ok()) << f.reason;
  EXPECT_EQ(checked, 201);
  EXPECT_GE(counters.position_solves, 201);
  // A kinematic analysis needs no mass matrix and no forces.
  EXPECT_EQ(m.counters().mass_matrix_evaluations, 0);
  EXPECT_EQ(m.counters().force_evaluations, 0);
}

// A crank at 1e4 rad/s turns 100 rad (101 instants over 1 s) or 10 rad (1001
// instants) between reporting instants: the analysis follows the branch it
// assembled on through the motion in between (subdividing the interval), so
// the slider is where a continuous motion puts it at every instant, to the
// positions' closure (1e-11 m) with round-off to spare: 1e-9 m. The other
// branch, x = r cos(th) - sqrt(l^2 - r^2 sin^2(th)), is 0.6 m or more away.
TEST(MultibodyKinematics, FastCrankStaysOnItsBranchBetweenCoarseInstants) {
  constexpr double w = 1e4;
  struct Geometry {
    double r, l;
  };
  for (const Geometry g : {Geometry{0.3, 1.0}, Geometry{0.1, 0.3}}) {
    const Model model = testing::SliderCrank(g.r, g.l, w);
    const Mechanism m(model);
    const Assembly assembled = Assemble(m, 0.0);
    ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
    for (const int points : {101, 1001}) {
      std::vector<double> times;
      for (int i = 0; i < points; ++i) times.push_back(static_cast<double>(i) / (points - 1));
      int checked = 0, off = 0;
      double worst_error_m = 0.0, worst_t_s = 0.0;
      KinematicCounters counters;
      const Point slider = At(2, 0.0);
      const spec::AnalysisFailure f = RunKinematics(
          m, assembled.q, times, KinematicOptions{}, [&](const MotionSample& s) {
            const double th = w * s.t_s, sn = std::sin(th), cs = std::cos(th);
            const double x = g.r * cs + std::sqrt(g.l * g.l - g.r * g.r * sn * sn);
            const double error = std::abs(m.PointPosition(slider, s.q).x() - x);
            if (error > kKinematicAgreement) ++off;
            if (error > worst_error_m) worst_error_m = error, worst_t_s = s.t_s;
            ++checked;
            return spec::AnalysisFailure::Ok();
          },
          &counters);
      ASSERT_TRUE(f.ok()) << f.reason;
      EXPECT_LE(worst_error_m, kKinematicAgreement)
          << "r = " << g.r << ", " << points << " points: " << off << " instants off, the worst at t = " << worst_t_s;
      // The reporting grid stays as asked; the motion in between is solved
      // at instants of its own.
      EXPECT_EQ(checked, points);
      EXPECT_GT(counters.position_solves, 2 * points);
    }
  }
}

// A slider-crank with the rod as long as the crank reaches a locking
// position at th = pi/2 (rod folded onto the crank, the slider at the
// pivot), where its two branches meet. With no instant there, the analysis
// does not carry on along either branch as if nothing happened: it names
// the interval and the lock.
TEST(MultibodyKinematics, BranchPointBetweenInstantsIsANamedAssemblyFailure) {
  constexpr double r = 0.5, w = 1.0;
  const Model model = testing::SliderCrank(r, r, w);
  const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  std::vector<double> times;
  for (int i = 0; i <= 8; ++i) times.push_back(0.25 * i);
  KinematicCounters counters;
  double last_t = -1.0;
  const spec::AnalysisFailure f = RunKinematics(
      m, assembled.q, times, KinematicOptions{}, [&](const MotionSample& s) {
        last_t = s.t_s;
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.kind, spec::FailureKind::kAssembly);
  EXPECT_EQ(last_t, 1.5);  // the last instant before th = pi/2
  EXPECT_THAT(f.reason, HasSubstr("changes assembly branch between t = "));
  EXPECT_THAT(f.reason, HasSubstr("locking position"));
  // The interval named brackets th = pi/2 within the finest subdivision,
  // 1/1024 of the 0.25 s between instants.
  double from_s = 0.0, to_s = 0.0;
  ASSERT_EQ(std::sscanf(f.reason.c_str(), "the mechanism changes assembly branch between t = %lf s and %lf s", &from_s,
                        &to_s),
            2)
      << f.reason;
  EXPECT_LT(from_s, std::numbers::pi / 2 / w);
  EXPECT_GE(to_s, std::numbers::pi / 2 / w);
  EXPECT_LE(to_s - from_s, 0.25 / 1024 * (1 + 1e-9));
}

// A uniform bar driven at constant speed about its end in a vertical plane:
// the driver torque balances gravity, tau = m g (L/2) cos(phi) (no angular
// acceleration), phi measured from the horizontal.
TEST(MultibodyKinematics, DrivenPendulumTorqueBalancesGravity) {
  constexpr double mass = 2.0, length = 0.8, g = 9.81, w = 1.5;
  Model model = testing::Pendulum(mass, length, std::numbers::pi / 2);  // horizontal at t = 0
  Driver d;
  d.joint = 0;
  d.profile.kind = Profile::Kind::kConstantRate;
  d.profile.start = 0.0;
  d.profile.rate = w;
  model.drivers.push_back(d);
  const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  KinematicOptions options;
  options.inverse_dynamics = true;
  std::vector<double> times;
  for (int i = 0; i <= 40; ++i) times.push_back(0.1 * i);
  KinematicCounters counters;
  constexpr double kTorqueAgreement = 1e-9;  // N m, of torques of order 10 N m
  const spec::AnalysisFailure f = RunKinematics(
      m, assembled.q, times, options, [&](const MotionSample& s) {
        const double phi = w * s.t_s;
        const double driver_torque = -s.lambda[m.row_of_driver(0)];
        EXPECT_NEAR(driver_torque, mass * g * 0.5 * length * std::cos(phi), kTorqueAgreement) << "t = " << s.t_s;
        // The pin carries the weight and the centripetal force.
        const Eigen::Vector2d pin_on_bar = s.lambda.segment<2>(m.first_row_of_joint(0));
        const Eigen::Vector2d centre = m.PointPosition(At(0, 0.0), s.q);
        const Eigen::Vector2d expected = mass * (-w * w * centre) - mass * Eigen::Vector2d(0.0, -g);
        EXPECT_NEAR((pin_on_bar - expected).norm(), 0.0, kTorqueAgreement);
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  EXPECT_TRUE(f.ok()) << f.reason;
}

TEST(MultibodyAssembly, DegreesOfFreedomAndRedundantJointsAreCounted) {
  // A four-bar (ground 1 m, crank 0.3, coupler 1.1, rocker 0.8): one degree
  // of freedom free, none once driven.
  auto four_bar = [](bool driven, bool redundant) {
    Model m;
    m.bodies.push_back(testing::Bar("crank", 1.0, 0.3, {0.0, 0.15}, std::numbers::pi / 2));
    m.bodies.push_back(testing::Bar("coupler", 1.0, 1.1, {0.5, 0.6}, 0.3));
    m.bodies.push_back(testing::Bar("rocker", 1.0, 0.8, {1.0, 0.4}, std::numbers::pi / 2));
    m.joints.push_back(testing::Revolute("A", At(kGround, 0.0), At(0, -0.15)));
    m.joints.push_back(testing::Revolute("B", At(0, 0.15), At(1, -0.55)));
    m.joints.push_back(testing::Revolute("C", At(1, 0.55), At(2, 0.4)));
    m.joints.push_back(testing::Revolute("D", At(kGround, 1.0), At(2, -0.4)));
    if (redundant) m.joints.push_back(testing::Revolute("D2", At(kGround, 1.0), At(2, -0.4)));
    if (driven) {
      Driver d;
      d.joint = 0;
      d.profile.start = std::numbers::pi / 2;
      m.drivers.push_back(d);
    }
    return m;
  };
  const Model free = four_bar(false, false), driven = four_bar(true, false), redundant = four_bar(false, true);
  const Assembly a = Assemble(Mechanism(free), 0.0);
  ASSERT_TRUE(a.failure.ok()) << a.failure.reason;
  EXPECT_EQ(a.degrees_of_freedom, 1);
  EXPECT_TRUE(a.redundant.empty());
  const Assembly b = Assemble(Mechanism(driven), 0.0);
  ASSERT_TRUE(b.failure.ok()) << b.failure.reason;
  EXPECT_EQ(b.degrees_of_freedom, 0);
  const Assembly c = Assemble(Mechanism(redundant), 0.0);
  ASSERT_TRUE(c.failure.ok()) << c.failure.reason;
  EXPECT_EQ(c.degrees_of_freedom, 1);
  EXPECT_THAT(c.redundant, ::testing::Contains(::testing::AnyOf("D", "D2")));
}

// The crank of a slider-crank whose rod is shorter than the crank cannot
// turn all the way: where the loop cannot close is a named failure.
TEST(MultibodyKinematics, DriverThatTearsTheLoopApartIsAFailedAnalysisNamingJointAndTime) {
  const Model model = testing::SliderCrank(0.5, 0.4, 1.0);
  const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  std::vector<double> times;
  for (int i = 0; i <= 100; ++i) times.push_back(0.02 * i);
  KinematicCounters counters;
  const spec::AnalysisFailure f = RunKinematics(
      m, assembled.q, times, KinematicOptions{}, [](const MotionSample&) { return spec::AnalysisFailure::Ok(); },
      &counters);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.kind, spec::FailureKind::kAssembly);
  EXPECT_THAT(f.reason, HasSubstr("t = "));
  EXPECT_THAT(f.reason, HasSubstr("joint '"));
}

}  // namespace
}  // namespace mbopt::multibody
