// The lumped dynamic formulation against analytic solutions of a single
// degree of freedom (free response; base excitation by a cosine bump), an
// energy invariant of an undamped multi-body system, and its failure paths.
#include "worker/lumped/lumped_dynamics.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "tests/testing/fake_clock.h"
#include "worker/lumped/lumped_model.h"

namespace mbopt::lumped {
namespace {

using ::testing::HasSubstr;

constexpr double kPi = 3.14159265358979323846;
// At rtol 1e-10 / atol 1e-13 the global error over a few periods stays far
// below this fraction of the response amplitude.
constexpr double kRelativeToAmplitude = 1e-6;

spec::Number Lit(double v) {
  spec::Number n;
  n.value = v;
  return n;
}

struct OneDof {
  double mass_kg = 2.0;
  double stiffness_n_per_m = 800.0;  // omega_n = 20 rad/s
  double damping_n_s_per_m = 8.0;    // zeta = 0.1
};

// One body moving along y on a spring-damper to the ground (or to a bump
// input), with outputs s (deflection) and a (acceleration).
spec::Scene OneDofScene(const OneDof& p, bool with_bump) {
  spec::Scene scene;
  scene.name = "one_dof";
  spec::Parameter k;
  k.name = "k";
  k.value_si = p.stiffness_n_per_m;
  scene.parameters.push_back(k);
  spec::LumpedModel m;
  spec::Body body;
  body.name = "mass";
  body.mass_kg = Lit(p.mass_kg);
  body.dofs = {spec::Dof::kY};
  m.bodies.push_back(body);
  spec::SpringDamper e;
  e.name = "spring";
  e.a.kind = spec::Attachment::Kind::kBody;
  e.a.index = 0;
  e.stiffness_n_per_m.param = 0;
  e.damping_n_s_per_m = Lit(p.damping_n_s_per_m);
  if (with_bump) {
    spec::GroundInput input;
    input.name = "road";
    input.bump.height_m = Lit(0.05);
    input.bump.length_m = Lit(2.0);
    input.bump.speed_m_per_s = Lit(4.0);
    input.bump.start_time_s = Lit(0.2);
    m.inputs.push_back(input);
    e.b.kind = spec::Attachment::Kind::kInput;
    e.b.index = 0;
  }
  m.elements.push_back(e);
  scene.model = m;
  spec::Output s;
  s.name = "s";
  s.kind = spec::ElementDeflectionOutput{0};
  spec::Output a;
  a.name = "a";
  spec::BodyAccelerationOutput acc;
  acc.body = 0;
  acc.axis = spec::Axis::kY;
  a.kind = acc;
  scene.outputs = {s, a};
  scene.time_grid = {0.0, 0.7, 36};  // the bump ends at 0.2 + 2 / 4 = 0.7 s
  scene.integrator.relative_tolerance = 1e-10;
  scene.integrator.absolute_tolerance = 1e-13;
  return scene;
}

TEST(LumpedDynamics, FreeResponseOfDampedOscillatorMatchesClosedForm) {
  const OneDof p;
  const spec::Scene scene = OneDofScene(p, false);
  LumpedDynamicsOptions options;
  const double x0 = 0.01;
  options.initial_q = Eigen::VectorXd::Constant(1, x0);
  const spec::AnalysisReport r = SimulateLumped(scene, {p.stiffness_n_per_m}, options);
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  const double wn = std::sqrt(p.stiffness_n_per_m / p.mass_kg);
  const double zeta = p.damping_n_s_per_m / (2 * std::sqrt(p.stiffness_n_per_m * p.mass_kg));
  const double wd = wn * std::sqrt(1 - zeta * zeta);
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double t = r.times_s[i];
    const double e = std::exp(-zeta * wn * t);
    const double x = x0 * e * (std::cos(wd * t) + zeta * wn / wd * std::sin(wd * t));
    const double v = -x0 * e * wn * wn / wd * std::sin(wd * t);
    const double a = -(p.stiffness_n_per_m * x + p.damping_n_s_per_m * v) / p.mass_kg;
    EXPECT_NEAR(r.outputs[0].series[0][i], x, kRelativeToAmplitude * x0) << "t = " << t;
    EXPECT_NEAR(r.outputs[1].series[0][i], a, kRelativeToAmplitude * x0 * wn * wn) << "t = " << t;
  }
}

// m x'' + c x' + k x = k u + c u' with u the bump, from rest: particular
// solution (constant + harmonic at the bump frequency) plus the homogeneous
// solution that starts at rest when the bump begins.
TEST(LumpedDynamics, BaseExcitationByCosineBumpMatchesClosedFormWithBdfAndAdams) {
  const OneDof p;
  const double m = p.mass_kg, k = p.stiffness_n_per_m, c = p.damping_n_s_per_m;
  const double h = 0.05, t0 = 0.2, w = 2 * kPi * 4.0 / 2.0;
  const double a11 = k - m * w * w, a12 = c * w;  // [a11 a12; -a12 a11] (B, D) = (-k h/2, c h w/2)
  const double det = a11 * a11 + a12 * a12;
  const double rhs1 = -k * h / 2, rhs2 = c * h * w / 2;
  const double B = (a11 * rhs1 - a12 * rhs2) / det;
  const double D = (a12 * rhs1 + a11 * rhs2) / det;
  const double wn = std::sqrt(k / m), zeta = c / (2 * std::sqrt(k * m));
  const double wd = wn * std::sqrt(1 - zeta * zeta);
  const double E = -(h / 2 + B);
  const double F = (zeta * wn * E - D * w) / wd;
  auto exact = [&](double t, double* s, double* a) {
    if (t <= t0) {
      *s = *a = 0;
      return;
    }
    const double tau = t - t0, ex = std::exp(-zeta * wn * tau);
    const double x = h / 2 + B * std::cos(w * tau) + D * std::sin(w * tau) +
                     ex * (E * std::cos(wd * tau) + F * std::sin(wd * tau));
    const double xd = -B * w * std::sin(w * tau) + D * w * std::cos(w * tau) +
                      ex * ((-zeta * wn * E + wd * F) * std::cos(wd * tau) +
                            (-zeta * wn * F - wd * E) * std::sin(wd * tau));
    const double u = h / 2 * (1 - std::cos(w * tau)), ud = h / 2 * w * std::sin(w * tau);
    *s = x - u;
    *a = -(k * (x - u) + c * (xd - ud)) / m;
  };
  const spec::Scene scene = OneDofScene(p, true);
  for (bool adams : {false, true}) {
    LumpedDynamicsOptions options;
    options.adams = adams;
    const spec::AnalysisReport r = SimulateLumped(scene, {k}, options);
    ASSERT_TRUE(r.ok()) << r.failure.reason;
    for (size_t i = 0; i < r.times_s.size(); ++i) {
      double s = 0, a = 0;
      exact(r.times_s[i], &s, &a);
      EXPECT_NEAR(r.outputs[0].series[0][i], s, kRelativeToAmplitude * h)
          << "t = " << r.times_s[i] << (adams ? " adams" : " bdf");
      EXPECT_NEAR(r.outputs[1].series[0][i], a, kRelativeToAmplitude * h * wn * wn)
          << "t = " << r.times_s[i] << (adams ? " adams" : " bdf");
    }
  }
}

TEST(LumpedDynamics, UndampedFreeVibrationConservesEnergy) {
  // A bar (heave + pitch) on two ground springs at +-0.5 m, with a second
  // body hanging on a spring from its front end: three coupled coordinates.
  spec::LumpedModel spec_model;
  spec::Body bar;
  bar.name = "bar";
  bar.mass_kg = Lit(10);
  bar.inertia_kg_m2 = Lit(2);
  bar.dofs = {spec::Dof::kY, spec::Dof::kRotation};
  spec::Body tip;
  tip.name = "tip";
  tip.mass_kg = Lit(1);
  tip.dofs = {spec::Dof::kY};
  spec_model.bodies = {bar, tip};
  auto spring = [](int body_a, double offset_x, int body_b, double k) {
    spec::SpringDamper e;
    e.name = "k";
    e.a.kind = spec::Attachment::Kind::kBody;
    e.a.index = body_a;
    e.a.offset_m.x = Lit(offset_x);
    if (body_b >= 0) {
      e.b.kind = spec::Attachment::Kind::kBody;
      e.b.index = body_b;
    }
    e.stiffness_n_per_m = Lit(k);
    return e;
  };
  spec_model.elements = {spring(0, 0.5, -1, 1000), spring(0, -0.5, -1, 1500),
                         spring(0, 0.5, 1, 300)};
  auto model = lumped::LumpedModel::Assemble(spec_model, {});
  ASSERT_TRUE(model.ok()) << model.status();
  spec::IntegratorSettings settings;
  settings.relative_tolerance = 1e-10;
  settings.absolute_tolerance = 1e-14;
  LumpedDynamicsOptions options;
  options.initial_q = Eigen::Vector3d(0.01, 0.02, -0.005);
  options.initial_qdot = Eigen::Vector3d(0.0, 0.1, 0.0);
  const Eigen::VectorXd& mass = model->mass_diagonal();
  const Eigen::MatrixXd& stiffness = model->stiffness();
  auto energy = [&](const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
    return 0.5 * v.dot(mass.cwiseProduct(v)) + 0.5 * q.dot(stiffness * q);
  };
  const double e0 = energy(options.initial_q, options.initial_qdot);
  std::vector<double> instants;
  for (int i = 0; i <= 100; ++i) instants.push_back(0.05 * i);
  // Energy drift of a dissipative-free linear system at rtol 1e-10.
  constexpr double kEnergyTolerance = 1e-6;
  int checked = 0;
  spec::AnalysisCounters counters;
  const spec::AnalysisFailure failure = IntegrateLumped(
      *model, instants, settings, options,
      [&](double, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
        EXPECT_NEAR(energy(q, v) / e0, 1.0, kEnergyTolerance);
        ++checked;
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  EXPECT_TRUE(failure.ok()) << failure.reason;
  EXPECT_EQ(checked, 101);
  EXPECT_GT(counters.time_steps, 0);
}

TEST(LumpedDynamics, StepLimitIsAFailedAnalysisWithReason) {
  spec::Scene scene = OneDofScene(OneDof(), true);
  scene.integrator.max_steps = 5;
  const spec::AnalysisReport r = SimulateLumped(scene, {800.0});
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kIntegrator);
  EXPECT_THAT(r.failure.reason, HasSubstr("step budget"));
  EXPECT_TRUE(r.outputs.empty());
  EXPECT_LE(r.counters.time_steps, 5);
}

// The budget's clock moves 1 s per reading: over its 3 s after a few
// right-hand sides.
TEST(LumpedDynamics, WallTimeLimitIsAFailedAnalysisWithReason) {
  const spec::Scene scene = OneDofScene(OneDof(), true);
  const mbopt::testing::SteppingClock clock(1.0);
  budget::AnalysisBudget budget = budget::AnalysisBudget(clock.AsClock(), nullptr).ForAnalysis(3.0, 0);
  LumpedDynamicsOptions options;
  options.budget = &budget;
  const spec::AnalysisReport r = SimulateLumped(scene, {800.0}, options);
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kTimeLimit);
  EXPECT_THAT(r.failure.reason, HasSubstr("wall-time limit of 3 s"));
  EXPECT_LE(r.counters.rhs_evaluations, 3);
}

TEST(LumpedDynamics, CancelledAnalysisIsAFailureOfItsOwnKind) {
  const spec::Scene scene = OneDofScene(OneDof(), true);
  const mbopt::testing::CancelAfter cancel(10);
  budget::AnalysisBudget budget(nullptr, cancel.AsFlag());
  LumpedDynamicsOptions options;
  options.budget = &budget;
  const spec::AnalysisReport r = SimulateLumped(scene, {800.0}, options);
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kCancelled) << r.failure.reason;
  EXPECT_THAT(r.failure.reason, HasSubstr("cancelled at t = "));
  EXPECT_LE(r.counters.rhs_evaluations, 10);
}

TEST(LumpedDynamics, UnusableParameterValueIsAFailedAnalysisNamingTheElement) {
  const spec::AnalysisReport r = SimulateLumped(OneDofScene(OneDof(), true), {-5.0});
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_THAT(r.failure.reason, HasSubstr("element \"spring\""));
}

TEST(LumpedDynamics, NoRequestedOutputMeansNoIntegration) {
  spec::Scene scene = OneDofScene(OneDof(), true);
  scene.outputs.clear();
  const spec::AnalysisReport r = SimulateLumped(scene, {800.0});
  EXPECT_TRUE(r.ok());
  EXPECT_TRUE(r.outputs.empty());
  EXPECT_EQ(r.counters.time_steps, 0);
  EXPECT_EQ(r.counters.rhs_evaluations, 0);
}

TEST(LumpedDynamics, ReportsOnlyTheRequestedOutputsInSceneOrder) {
  spec::Scene scene = OneDofScene(OneDof(), true);
  std::swap(scene.outputs[0], scene.outputs[1]);
  scene.outputs.pop_back();  // only the acceleration is left
  const spec::AnalysisReport r = SimulateLumped(scene, {800.0});
  ASSERT_TRUE(r.ok());
  ASSERT_EQ(r.outputs.size(), 1u);
  EXPECT_EQ(r.outputs[0].name, "a");
  EXPECT_EQ(r.outputs[0].series[0].size(), r.times_s.size());
  EXPECT_EQ(r.formulation, spec::Formulation::kDynamic);
}

// body_displacement and body_velocity of the free damped oscillator against
// the closed form x(t), x'(t), to the same fraction of the amplitude as the
// deflection and acceleration above.
TEST(LumpedDynamics, BodyDisplacementAndVelocityMatchTheClosedForm) {
  const OneDof p;
  spec::Scene scene = OneDofScene(p, false);
  spec::BodyAccelerationOutput displacement;
  displacement.body = 0;
  displacement.quantity = spec::BodyAccelerationOutput::Quantity::kDisplacement;
  spec::BodyAccelerationOutput velocity = displacement;
  velocity.quantity = spec::BodyAccelerationOutput::Quantity::kVelocity;
  scene.outputs.push_back({"y", displacement});
  scene.outputs.push_back({"v", velocity});
  LumpedDynamicsOptions options;
  const double x0 = 0.01;
  options.initial_q = Eigen::VectorXd::Constant(1, x0);
  const spec::AnalysisReport r = SimulateLumped(scene, {p.stiffness_n_per_m}, options);
  ASSERT_TRUE(r.ok()) << r.failure.reason;
  ASSERT_EQ(r.outputs.size(), 4u);
  const double wn = std::sqrt(p.stiffness_n_per_m / p.mass_kg);
  const double zeta = p.damping_n_s_per_m / (2 * std::sqrt(p.stiffness_n_per_m * p.mass_kg));
  const double wd = wn * std::sqrt(1 - zeta * zeta);
  for (size_t i = 0; i < r.times_s.size(); ++i) {
    const double t = r.times_s[i];
    const double e = std::exp(-zeta * wn * t);
    const double x = x0 * e * (std::cos(wd * t) + zeta * wn / wd * std::sin(wd * t));
    const double v = -x0 * e * wn * wn / wd * std::sin(wd * t);
    EXPECT_NEAR(r.outputs[2].series[0][i], x, kRelativeToAmplitude * x0) << "t = " << t;
    EXPECT_NEAR(r.outputs[3].series[0][i], v, kRelativeToAmplitude * x0 * wn) << "t = " << t;
  }
}

TEST(LumpedModel, KinksAreTheBumpStartsAndEndsInsideTheInterval) {
  spec::Scene scene = OneDofScene(OneDof(), true);
  auto model = lumped::LumpedModel::Assemble(std::get<spec::LumpedModel>(scene.model), {800.0});
  ASSERT_TRUE(model.ok());
  EXPECT_THAT(
      model->KinkTimes(0.0, 1.0),
      ::testing::ElementsAre(::testing::DoubleNear(0.2, 1e-12), ::testing::DoubleNear(0.7, 1e-12)));
  EXPECT_THAT(model->KinkTimes(0.0, 0.5),
              ::testing::ElementsAre(::testing::DoubleNear(0.2, 1e-12)));
}

}  // namespace
}  // namespace mbopt::lumped
