// The start of forward dynamics at tight tolerances: mechanisms that are
// already moving at t = 0 (an initial joint rate, a free body carried by a
// driven joint) must start at rtol 1e-8 / atol 1e-10, the tolerances the
// shipped multibody examples use, and give the right motion.
#include <cmath>
#include <iostream>
#include <numbers>
#include <optional>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/multibody/mechanisms.h"
#include "tests/multibody/time_grid.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/scene_analysis.h"

namespace mbopt::multibody {
namespace {

using testing::At;
using testing::Grid;

ForwardDynamicsOptions Tight() {
  ForwardDynamicsOptions options;
  options.relative_tolerance = 1e-8;
  options.absolute_tolerance = 1e-10;
  return options;
}

// Compound pendulums (uniform bars pinned at one end) flung from their
// start at rates from a small swing to over the top: a 1 kg, 0.5 m bar from
// the bottom and a 20 g, 30 mm one from 0.5 rad (lengths and masses of
// Andrews' mechanism). The energy is an exact invariant.
TEST(ForwardDynamicsStart, PendulumWithAnInitialRateStartsAtTightTolerances) {
  struct Case {
    double mass_kg, length_m, theta0_rad, rate_rad_per_s;
  };
  const Case cases[] = {{1.0, 0.5, 0.0, 0.5}, {1.0, 0.5, 0.0, 3.0}, {1.0, 0.5, 0.0, 20.0}, {0.02, 0.03, 0.5, 50.0}};
  for (const Case& c : cases) {
    Model model = testing::Pendulum(c.mass_kg, c.length_m, c.theta0_rad);
    model.joints[0].initial_rate = c.rate_rad_per_s;
    const Mechanism m(model);
    const Assembly assembled = Assemble(m, 0.0);
    ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
    const double e0 = m.KineticEnergy(assembled.v) + m.PotentialEnergy(assembled.q);
    // The energy's scale: the kinetic energy plus the swing's potential range.
    const double scale = m.KineticEnergy(assembled.v) + c.mass_kg * 9.81 * c.length_m;
    ForwardDynamicsCounters counters;
    double worst = 0.0;
    const spec::AnalysisFailure f = IntegrateForward(
        m, 0.0, assembled.q, assembled.v, Grid(1.0, 100), Tight(),
        [&](const MotionSample& s) {
          worst = std::max(worst, std::abs(m.KineticEnergy(s.v) + m.PotentialEnergy(s.q) - e0));
          return spec::AnalysisFailure::Ok();
        },
        &counters);
    std::cout << c.mass_kg << " kg, " << c.length_m << " m at " << c.rate_rad_per_s
              << " rad/s: " << (f.ok() ? "ok" : f.reason) << ", " << counters.steps << " steps, energy error "
              << worst / scale << " of " << scale << " J (" << counters.error_test_failures << " error-test and "
              << counters.convergence_failures << " convergence failures)\n";
    ASSERT_TRUE(f.ok()) << f.reason;
    // rtol 1e-8 per step; over 1 s (up to 8 turns) the energy drifts by up
    // to 7.5e-7 of its scale (measured 8.6e-11 to 7.5e-7).
    EXPECT_LT(worst, 2e-5 * scale) << c.rate_rad_per_s << " rad/s";
  }
}

// A free link on a driven arm (a flail): the hub turns at 10 rad/s and the
// tip link, pinned to the arm's end, swings freely. Started turning with the
// arm (elbow rate 0) it stays aligned with it, a relative equilibrium in
// which the centrifugal force pulls it straight; started with other rates it
// swings, and its energy in the rotating frame (the Jacobi integral) is
// exact. With no elbow rate given, assembly's minimum-norm velocities leave
// the tip nearly still (elbow rate -10.4 rad/s): that start failed at t = 0.
TEST(ForwardDynamicsStart, FreeLinkOnADrivenArmStartsAtTightTolerances) {
  const std::optional<double> elbow_rates[] = {std::nullopt, 0.0, -25.0};
  for (const std::optional<double>& elbow_rate : elbow_rates) {
    Model model;
    model.bodies.push_back(testing::Bar("arm", 2.0, 0.4, {0.2, 0.0}, 0.0));
    model.bodies.push_back(testing::Bar("tip", 0.5, 0.2, {0.5, 0.0}, 0.0));
    model.joints.push_back(testing::Revolute("hub", At(kGround, 0.0), At(0, -0.2)));
    model.joints.push_back(testing::Revolute("elbow", At(0, 0.2), At(1, -0.1)));
    model.joints[1].initial_rate = elbow_rate;
    Driver d;
    d.joint = 0;
    d.profile.kind = Profile::Kind::kConstantRate;
    d.profile.rate = 10.0;
    model.drivers.push_back(d);
    const Mechanism m(model);
    const Assembly assembled = Assemble(m, 0.0);
    ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
    // T - Omega L about the hub: the driver's work Omega dL/dt is all the
    // energy that enters.
    const auto jacobi_integral = [&](const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
      double angular_momentum = 0.0;
      for (size_t b = 0; b < model.bodies.size(); ++b) {
        const int i = 3 * static_cast<int>(b);
        angular_momentum +=
            model.bodies[b].mass_kg * (q[i] * v[i + 1] - q[i + 1] * v[i]) + model.bodies[b].inertia_kg_m2 * v[i + 2];
      }
      return m.KineticEnergy(v) - d.profile.rate * angular_momentum;
    };
    ForwardDynamicsCounters counters;
    double worst = 0.0, jacobi_at_end = NAN;
    const spec::AnalysisFailure f = IntegrateForward(
        m, 0.0, assembled.q, assembled.v, Grid(1.0, 100), Tight(),
        [&](const MotionSample& s) {
          worst = std::max(worst, std::abs(m.JointCoordinate(1, s.q)));
          jacobi_at_end = jacobi_integral(s.q, s.v);
          return spec::AnalysisFailure::Ok();
        },
        &counters);
    std::cout << "elbow rate " << m.JointRate(1, assembled.q, assembled.v) << " rad/s: " << (f.ok() ? "ok" : f.reason)
              << ", " << counters.steps << " steps, largest elbow angle " << worst << " rad\n";
    ASSERT_TRUE(f.ok()) << f.reason;
    if (elbow_rate == 0.0) {
      constexpr double kStraight = 1e-6;  // rad: the integration's error only (2.5e-7 measured)
      EXPECT_LT(worst, kStraight);
    } else {
      EXPECT_GT(worst, 0.1);  // it swings
    }
    const double jacobi = jacobi_integral(assembled.q, assembled.v);
    EXPECT_NEAR(jacobi_at_end, jacobi, 1e-5 * std::abs(jacobi) + 1e-9);
  }
}

// The isolator (examples/isolator: an arm on a shaken base, starting to move
// with the base at 0.25 m/s) at rtol 1e-10 / atol 1e-12 failed at its first
// steps with fixed multiplier weights; it must run and agree with the
// scene's own tolerances (rtol 1e-8) to within theirs.
TEST(ForwardDynamicsStart, IsolatorRunsAtRtol1e10) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile("examples/isolator/isolator.scene.textproto");
  ASSERT_TRUE(scene.ok()) << scene.status();
  std::vector<double> defaults;
  for (const spec::Parameter& p : scene->parameters) defaults.push_back(p.value_si);
  const spec::AnalysisReport shipped = AnalyzeMultibodyScene(*scene, defaults);
  ASSERT_TRUE(shipped.ok()) << shipped.failure.reason;
  scene->integrator.relative_tolerance = 1e-10;
  scene->integrator.absolute_tolerance = 1e-12;
  const spec::AnalysisReport tight = AnalyzeMultibodyScene(*scene, defaults);
  ASSERT_TRUE(tight.ok()) << tight.failure.reason;
  const std::vector<double>& angle = tight.outputs[0].series[0];
  const std::vector<double>& angle_shipped = shipped.outputs[0].series[0];
  ASSERT_EQ(angle.size(), angle_shipped.size());
  double difference = 0.0;
  for (size_t k = 0; k < angle.size(); ++k) difference = std::max(difference, std::abs(angle[k] - angle_shipped[k]));
  std::cout << "isolator arm angle, rtol 1e-10 against 1e-8: " << difference << " rad\n";
  constexpr double kAgreement = 1e-8;  // rad, of a swing of 0.07 rad: 7.6e-10 measured
  EXPECT_LT(difference, kAgreement);
}

// An absolute tolerance below the coordinates' round-off cannot be met
// (IDAS creeps on at steps of 1e-12 s until the step budget is spent): the
// failure says when, which joint's rows and what to change.
TEST(ForwardDynamicsStart, AFailureAtTheStartSaysWhatToTry) {
  Model model = testing::Pendulum(1.0, 0.5, 0.3);
  model.joints[0].initial_rate = 5.0;
  const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  ForwardDynamicsOptions options;
  options.relative_tolerance = 1e-15;
  options.absolute_tolerance = 1e-20;
  options.max_steps = 2000;
  ForwardDynamicsCounters counters;
  const spec::AnalysisFailure f = IntegrateForward(
      m, 0.0, assembled.q, assembled.v, Grid(1.0, 10), options,
      [](const MotionSample&) { return spec::AnalysisFailure::Ok(); }, &counters);
  std::cout << f.reason << "\n";
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.kind, spec::FailureKind::kIntegrator);
  EXPECT_NE(f.reason.find("near t = "), std::string::npos) << f.reason;
  EXPECT_NE(f.reason.find("joint 'pin'"), std::string::npos) << f.reason;
  EXPECT_NE(f.reason.find("a looser absolute_tolerance (now 1e-20"), std::string::npos) << f.reason;
  EXPECT_NE(f.reason.find("at the start"), std::string::npos) << f.reason;
  EXPECT_NE(f.reason.find("a larger integrator max_steps (now 2000)"), std::string::npos) << f.reason;
}

}  // namespace
}  // namespace mbopt::multibody
