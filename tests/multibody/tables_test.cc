// Tabulated drivers (natural cubic splines) and force curves (linear tables
// that are never extrapolated).
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/multibody/mechanisms.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/kinematic_analysis.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/scene_analysis.h"

namespace mbopt::multibody {
namespace {

using ::testing::HasSubstr;
using testing::At;

TEST(CubicSpline, FollowsASmoothFunctionWithItsDerivatives) {
  std::vector<double> t, y;
  for (int k = 0; k <= 100; ++k) {
    t.push_back(0.02 * k);
    y.push_back(std::sin(t.back()));
  }
  const CubicSpline spline(t, y);
  double v = 0, dv = 0, d2v = 0;
  // Knots are reproduced exactly (to round-off).
  ASSERT_TRUE(spline.Evaluate(t[37], &v, &dv, &d2v));
  EXPECT_NEAR(v, y[37], 1e-15);
  // Between knots, away from the natural ends: h = 0.02 gives errors of
  // h^4 ~ 2e-7 in the value, h^2 ~ 4e-4 in the second derivative.
  for (double x = 0.3; x < 1.7; x += 0.013) {
    ASSERT_TRUE(spline.Evaluate(x, &v, &dv, &d2v));
    EXPECT_NEAR(v, std::sin(x), 1e-7);
    EXPECT_NEAR(dv, std::cos(x), 1e-5);
    EXPECT_NEAR(d2v, -std::sin(x), 1e-3);
  }
  EXPECT_FALSE(spline.Evaluate(2.1, &v, &dv, &d2v));  // no extrapolation
}

// A driven pendulum whose angle follows a table: the kinematic analysis
// reproduces the table's spline.
TEST(TabulatedDriver, DrivesTheJointThroughTheTable) {
  Model model = testing::Pendulum(1.0, 1.0, std::numbers::pi / 2);
  Driver d;
  d.joint = 0;
  d.profile.kind = Profile::Kind::kTabulated;
  std::vector<double> t, angle;
  for (int k = 0; k <= 20; ++k) {
    t.push_back(0.1 * k);
    angle.push_back(0.5 * t.back() * t.back());
  }
  d.profile.table = CubicSpline(t, angle);
  model.drivers.push_back(d);
  ASSERT_TRUE(model.Validate().ok()) << model.Validate();
  const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  KinematicCounters counters;
  int checked = 0;
  const spec::AnalysisFailure f = RunKinematics(
      m, assembled.q, t, KinematicOptions{}, [&](const MotionSample& s) {
        EXPECT_NEAR(m.JointCoordinate(0, s.q), 0.5 * s.t_s * s.t_s, 1e-10) << "t = " << s.t_s;
        ++checked;
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  EXPECT_TRUE(f.ok()) << f.reason;
  EXPECT_EQ(checked, 21);
}

// A mass on a horizontal prismatic joint between two springs' worth of
// stiffness: with a linear force table instead of the stiffness the motion
// is the same.
Model SpringMass(bool tabulated, double table_half_width_m, double x0_m = 1.2, double rate_m_per_s = 0.0) {
  Model m;
  Body b;
  b.name = "mass";
  b.mass_kg = 2.0;
  b.inertia_kg_m2 = 0.1;
  b.position_m = {x0_m, 0.0};
  m.bodies.push_back(b);
  Joint slide;
  slide.name = "slide";
  slide.kind = JointKind::kPrismatic;
  slide.a = At(kGround, 0.0);
  slide.b = At(0, 0.0);
  slide.initial_value = x0_m;
  slide.initial_rate = rate_m_per_s;
  m.joints.push_back(slide);
  SpringDamper s;
  s.name = "spring";
  s.a = At(kGround, 0.0);
  s.b = At(0, 0.0);
  s.free_length_m = 1.0;
  s.stiffness_n_per_m = 800.0;
  if (tabulated) {
    s.stiffness_n_per_m = 0.0;
    s.deflection_curve = LinearTable{{-table_half_width_m, table_half_width_m},
                                     {-800.0 * table_half_width_m, 800.0 * table_half_width_m}};
  }
  m.springs.push_back(s);
  return m;
}

std::vector<double> Motion(const Model& model, spec::AnalysisFailure* failure) {
  const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  EXPECT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  std::vector<double> t, x;
  for (int k = 0; k <= 100; ++k) t.push_back(0.01 * k);
  ForwardDynamicsOptions options;
  options.relative_tolerance = 1e-10;
  options.absolute_tolerance = 1e-12;
  ForwardDynamicsCounters counters;
  *failure = IntegrateForward(m, 0.0, assembled.q, assembled.v, t, options,
                              [&](const MotionSample& s) {
                                x.push_back(s.q[0]);
                                return spec::AnalysisFailure::Ok();
                              },
                              &counters);
  return x;
}

TEST(ForceCurve, ALinearTableMovesLikeTheStiffness) {
  spec::AnalysisFailure f;
  const std::vector<double> linear = Motion(SpringMass(false, 0.0), &f);
  ASSERT_TRUE(f.ok()) << f.reason;
  const std::vector<double> table = Motion(SpringMass(true, 0.5), &f);
  ASSERT_TRUE(f.ok()) << f.reason;
  ASSERT_EQ(linear.size(), table.size());
  // The same equations up to round-off in the interpolation, which steers
  // the two integrations (rtol 1e-10 over 1 s) apart by ~1e-9 m.
  for (size_t k = 0; k < linear.size(); ++k) EXPECT_NEAR(table[k], linear[k], 1e-7);
}

// From 0.05 m at 2 m/s the mass swings 0.112 m about the free length
// (omega = 20 rad/s); a table over +-0.1 m is left mid-swing: a failed
// analysis naming the spring, not an extrapolation.
TEST(ForceCurve, LeavingTheTableIsAFailedAnalysisNamingTheSpring) {
  spec::AnalysisFailure f;
  Motion(SpringMass(true, 0.1, 1.05, 2.0), &f);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.kind, spec::FailureKind::kModelValidity);
  EXPECT_THAT(f.reason, HasSubstr("spring 'spring' left the range of its force table"));
}

// The time a failure's reason names ("... at t = 0.0321 s ..."); NaN if none.
double NamedTime(const std::string& reason) {
  const size_t at = reason.find("at t = ");
  double t = NAN;
  if (at == std::string::npos || std::sscanf(reason.c_str() + at, "at t = %lf", &t) != 1) return NAN;
  return t;
}

// The same swing, x - 1 = 0.05 cos(20 t) + 0.1 sin(20 t) = 0.1118 sin(20 t +
// 0.4636), reaches the table's end, 0.1 m, at t = (asin(0.1 / 0.1118) -
// 0.4636) / 20 = 0.032175 s. The analysis ends there at once: the reason
// names that time, and the integrator took the steps the swing needs up to
// it, not its whole step budget at the table's edge.
TEST(ForceCurve, LeavingTheTableEndsTheAnalysisAtOnceNamingTheTime) {
  const Model model = SpringMass(true, 0.1, 1.05, 2.0);
  const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  std::vector<double> t;
  for (int k = 0; k <= 100; ++k) t.push_back(0.01 * k);
  ForwardDynamicsOptions options;
  options.relative_tolerance = 1e-10;
  options.absolute_tolerance = 1e-12;
  ForwardDynamicsCounters counters;
  int instants = 0;
  const spec::AnalysisFailure f = IntegrateForward(m, 0.0, assembled.q, assembled.v, t, options,
                                                   [&](const MotionSample&) {
                                                     ++instants;
                                                     return spec::AnalysisFailure::Ok();
                                                   },
                                                   &counters);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.kind, spec::FailureKind::kModelValidity);
  EXPECT_THAT(f.reason, HasSubstr("spring 'spring' left the range of its force table"));
  const double w = 20.0, amplitude = std::hypot(0.05, 0.1), phase = std::atan2(0.05, 0.1);
  const double t_leave = (std::asin(0.1 / amplitude) - phase) / w;
  // The reason prints 6 significant digits.
  EXPECT_NEAR(NamedTime(f.reason), t_leave, 1e-6) << f.reason;
  EXPECT_EQ(instants, 4);  // 0, 0.01, 0.02 and 0.03 s lie before it
  // A third of a period at rtol 1e-10 takes a few hundred steps; stepping at
  // the edge until the integrator gave up took its budget (1e5).
  EXPECT_LT(counters.steps, 1000);
  EXPECT_LT(counters.residual_evaluations, 5000);
}

// The isolator (examples/isolator) with its shaker's motion tabulated up to
// the time grid's end, as docs/scene.md allows: the analysis reaches the last
// instant and moves the arm as the harmonic profile the table samples does.
TEST(TabulatedDriver, ATableThatEndsAtTheGridsEndIsFollowedToTheEnd) {
  absl::StatusOr<spec::Scene> tabulated = spec::io::LoadSceneFile("tests/multibody/isolator_tabulated.scene.textproto");
  ASSERT_TRUE(tabulated.ok()) << tabulated.status();
  absl::StatusOr<spec::Scene> harmonic = spec::io::LoadSceneFile("examples/isolator/isolator.scene.textproto");
  ASSERT_TRUE(harmonic.ok()) << harmonic.status();
  harmonic->time_grid = tabulated->time_grid;
  ASSERT_EQ(std::get<spec::MultibodyModel>(tabulated->model).drivers[0].times_s.back(), tabulated->time_grid.end_s);
  const std::vector<double> design = {2000.0, 20.0};
  const spec::AnalysisReport from_table = AnalyzeMultibodyScene(*tabulated, design);
  ASSERT_TRUE(from_table.ok()) << from_table.failure.reason;
  const spec::AnalysisReport from_sine = AnalyzeMultibodyScene(*harmonic, design);
  ASSERT_TRUE(from_sine.ok()) << from_sine.failure.reason;
  ASSERT_EQ(from_table.times_s.size(), 101u);
  EXPECT_EQ(from_table.times_s.back(), 0.5);
  const std::vector<double>& angle_table = from_table.outputs[0].series[0];
  const std::vector<double>& angle_sine = from_sine.outputs[0].series[0];
  ASSERT_EQ(angle_table.size(), angle_sine.size());
  double swing = 0.0;
  for (double a : angle_sine) swing = std::max(swing, std::abs(a - angle_sine[0]));
  ASSERT_GT(swing, 1e-4);
  // The spline through 32 points per period gets the shaker's acceleration
  // right to 0.2 %; the arm's angle follows to 1 % of its swing.
  for (size_t k = 0; k < angle_table.size(); ++k) {
    EXPECT_NEAR(angle_table[k], angle_sine[k], 0.01 * swing) << "t = " << from_table.times_s[k];
  }
}

// A force factor whose table ends before the last instant (a model built in
// code; the scene loader refuses it): the integration stops at the table's
// end and says so, instead of cutting its step there until it gives up.
TEST(TabulatedDriver, ATableThatEndsBeforeTheLastInstantIsNamed) {
  Model model = SpringMass(false, 0.0);
  Profile factor;
  factor.kind = Profile::Kind::kTabulated;
  factor.table = CubicSpline({0.0, 0.25, 0.5}, {0.0, 1.0, 0.5});
  model.point_forces.push_back(PointForce{At(0, 0.0), Eigen::Vector2d(3.0, 0.0), factor});
  spec::AnalysisFailure f;
  Motion(model, &f);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.kind, spec::FailureKind::kModelValidity) << f.reason;
  EXPECT_THAT(f.reason, HasSubstr("a tabulated profile ends at t = 0.5 s, before the instant t = 0.51 s"));
}

// A mass on a frictionless slide pushed by F0 sin(w t) from rest:
// x = x0 + F0 / (m w) (t - sin(w t) / w).
TEST(TimeVaryingForce, HarmonicForceMovesTheMassAsTheClosedForm) {
  constexpr double m_kg = 2.0, f0 = 3.0, w = 5.0, x0 = 1.0;
  Model model = SpringMass(false, 0.0, x0);
  model.springs.clear();
  Profile factor;
  factor.kind = Profile::Kind::kHarmonic;
  factor.amplitude = 1.0;
  factor.angular_frequency_rad_per_s = w;
  model.point_forces.push_back(PointForce{At(0, 0.0), Eigen::Vector2d(f0, 0.0), factor});
  ASSERT_EQ(model.bodies[0].mass_kg, m_kg);
  spec::AnalysisFailure f;
  const std::vector<double> x = Motion(model, &f);
  ASSERT_TRUE(f.ok()) << f.reason;
  ASSERT_EQ(x.size(), 101u);
  constexpr double kAgreement = 1e-9;  // m, at rtol 1e-10 over 1 s
  for (size_t k = 0; k < x.size(); ++k) {
    const double t = 0.01 * static_cast<double>(k);
    EXPECT_NEAR(x[k], x0 + f0 / (m_kg * w) * (t - std::sin(w * t) / w), kAgreement) << "t = " << t;
  }
}

// A mass on a vertical slide hung on a spring from a ground point that moves
// as y = A sin(W t) (a base excitation, no gravity), from rest:
// x = A w^2 / (w^2 - W^2) (sin(W t) - (W / w) sin(w t)), w^2 = k / m.
TEST(InputPoint, BaseExcitationMovesTheMassAsTheClosedForm) {
  constexpr double m_kg = 2.0, k = 800.0, a = 0.01, big_w = 7.0;
  const double w = std::sqrt(k / m_kg);
  Model model;
  Body b;
  b.name = "mass";
  b.mass_kg = m_kg;
  b.inertia_kg_m2 = 0.1;
  b.position_m = {0.0, 1.0};
  model.bodies.push_back(b);
  Joint slide;
  slide.name = "slide";
  slide.kind = JointKind::kPrismatic;
  slide.axis_angle_rad = std::numbers::pi / 2;
  slide.a = At(kGround, 0.0);
  slide.b = At(0, 0.0);
  slide.initial_value = 1.0;
  slide.initial_rate = 0.0;
  model.joints.push_back(slide);
  InputPoint base;
  base.name = "base";
  base.displacement.kind = Profile::Kind::kHarmonic;
  base.displacement.amplitude = a;
  base.displacement.angular_frequency_rad_per_s = big_w;
  model.inputs.push_back(base);
  SpringDamper s;
  s.name = "spring";
  s.a = Point{kGround, Eigen::Vector2d::Zero(), "base", 0};
  s.b = At(0, 0.0);
  s.free_length_m = 1.0;
  s.stiffness_n_per_m = k;
  model.springs.push_back(s);
  ASSERT_TRUE(model.Validate().ok()) << model.Validate();
  const Mechanism mech(model);
  const Assembly assembled = Assemble(mech, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  std::vector<double> t;
  for (int i = 0; i <= 200; ++i) t.push_back(0.01 * i);
  ForwardDynamicsOptions options;
  options.relative_tolerance = 1e-10;
  options.absolute_tolerance = 1e-12;
  ForwardDynamicsCounters counters;
  constexpr double kAgreement = 1e-9;  // m, of a 2 cm motion, rtol 1e-10 over 2 s
  const spec::AnalysisFailure f = IntegrateForward(
      mech, 0.0, assembled.q, assembled.v, t, options, [&](const MotionSample& sample) {
        const double x = a * w * w / (w * w - big_w * big_w) *
                         (std::sin(big_w * sample.t_s) - big_w / w * std::sin(w * sample.t_s));
        EXPECT_NEAR(sample.q[1] - 1.0, x, kAgreement) << "t = " << sample.t_s;
        EXPECT_NEAR(mech.PointPosition(s.a, sample.q, sample.t_s).y(), a * std::sin(big_w * sample.t_s), 1e-15);
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  EXPECT_TRUE(f.ok()) << f.reason;
  // A joint may not use an input point.
  Model bad = model;
  bad.joints[0].a = Point{kGround, Eigen::Vector2d::Zero(), "base", 0};
  EXPECT_FALSE(bad.Validate().ok());
}

}  // namespace
}  // namespace mbopt::multibody
