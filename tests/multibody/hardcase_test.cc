// Hard cases of the multibody engine (label hardcase, docs/hardcases.md):
// each ends converged or as a named failed analysis, never a crash or a
// silent wrong number.
#include <cmath>
#include <iostream>
#include <numbers>

#include <gtest/gtest.h>

#include "tests/multibody/mechanisms.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/kinematic_analysis.h"
#include "worker/multibody/mechanism.h"

namespace mbopt::multibody {
namespace {

using testing::At;

// A slider-crank whose rod is only 0.1 % longer than the crank: at a
// quarter turn the rod stands almost perpendicular to the guide and the
// constraint Jacobian is nearly singular (rcond ~ 1e-3 of its usual value).
// The kinematics must still follow the closed form, or stop with a named
// lock-up.
TEST(MultibodyHardcase, SliderCrankPassingNearItsSingularPosition) {
  constexpr double r = 0.3, l = 0.3003, w = 2.0 * std::numbers::pi;
  const Model model = testing::SliderCrank(r, l, w);
  const Mechanism m(model);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  std::vector<double> times;
  for (int i = 0; i <= 400; ++i) times.push_back(0.0025 * i);
  double worst = 0.0;
  KinematicCounters counters;
  const spec::AnalysisFailure f = RunKinematics(
      m, assembled.q, times, KinematicOptions{}, [&](const MotionSample& s) {
        const double th = w * s.t_s;
        const double x = r * std::cos(th) + std::sqrt(l * l - r * r * std::sin(th) * std::sin(th));
        worst = std::max(worst, std::abs(m.PointPosition(At(2, 0.0), s.q).x() - x));
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  std::cout << "[hardcase] slider-crank with l/r = 1.001: ";
  if (f.ok()) {
    std::cout << "ok, largest position error " << worst << " m";
  } else {
    std::cout << "failed: " << f.reason;
  }
  std::cout << ", " << counters.position_solves << " position solves\n";
  if (f.ok()) {
    constexpr double kNearSingularAgreement = 1e-8;  // m: Newton to 1e-11 on a Jacobian 1e3 times worse conditioned
    EXPECT_LT(worst, kNearSingularAgreement);
  } else {
    EXPECT_EQ(f.kind, spec::FailureKind::kAssembly);
    EXPECT_NE(f.reason.find("t = "), std::string::npos) << f.reason;
  }
}

// Two masses in series on a slide, springs 1e6 apart in stiffness (100 N/m
// and 1e8 N/m): a stiff system that IDAS's BDF must integrate without
// resolving the fast mode's oscillation (a few thousand steps, not millions).
TEST(MultibodyHardcase, StiffnessRatioOfAMillion) {
  Model m;
  for (int i = 0; i < 2; ++i) {
    Body b;
    b.name = i == 0 ? "heavy" : "light";
    b.mass_kg = 1.0;
    b.inertia_kg_m2 = 0.1;
    b.position_m = {1.0 + i * 0.1, 0.0};
    m.bodies.push_back(b);
    Joint slide;
    slide.name = "slide" + std::to_string(i);
    slide.kind = JointKind::kPrismatic;
    slide.a = At(kGround, 0.0);
    slide.b = At(i, 0.0);
    m.joints.push_back(slide);
  }
  m.joints[0].initial_value = 1.1;  // the soft spring starts stretched by 0.1 m
  m.joints[1].initial_value = 1.2;
  SpringDamper soft;
  soft.name = "soft";
  soft.a = At(kGround, 0.0);
  soft.b = At(0, 0.0);
  soft.free_length_m = 1.0;
  soft.stiffness_n_per_m = 100.0;
  m.springs.push_back(soft);
  SpringDamper stiff;
  stiff.name = "stiff";
  stiff.a = At(0, 0.0);
  stiff.b = At(1, 0.0);
  stiff.free_length_m = 0.1;
  stiff.stiffness_n_per_m = 1e8;
  stiff.damping_n_s_per_m = 10.0;
  m.springs.push_back(stiff);
  const Mechanism mech(m);
  const Assembly assembled = Assemble(mech, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  EXPECT_EQ(assembled.degrees_of_freedom, 2);
  std::vector<double> times;
  for (int i = 0; i <= 100; ++i) times.push_back(0.01 * i);
  ForwardDynamicsOptions options;
  ForwardDynamicsCounters counters;
  double worst_energy_rise = 0.0, e0 = NAN;
  const spec::AnalysisFailure f = IntegrateForward(
      mech, 0.0, assembled.q, assembled.v, times, options, [&](const MotionSample& s) {
        const double e = mech.KineticEnergy(s.v) + mech.PotentialEnergy(s.q);
        if (std::isnan(e0)) e0 = e;
        worst_energy_rise = std::max(worst_energy_rise, e - e0);
        return spec::AnalysisFailure::Ok();
      },
      &counters);
  std::cout << "[hardcase] stiffness ratio 1e6: " << (f.ok() ? "ok" : "failed: " + f.reason) << ", "
            << counters.steps << " steps\n";
  ASSERT_TRUE(f.ok()) << f.reason;
  // The slow mode has a period of 0.9 s: resolving it takes hundreds of
  // steps; resolving the fast one (0.6 ms, 1600 periods in 1 s) would take
  // tens of thousands. Between the two, the count follows how much the
  // lightly damped fast mode is excited by the corrector's round-off, so it
  // moves with the Newton matrix's rounding: 3468 steps with IDAS's
  // difference quotients, 5141 with the exact matrix.
  EXPECT_LT(counters.steps, 10000);
  // Damped: the energy never grows beyond the integration tolerance.
  constexpr double kEnergyTolerance = 1e-3;  // J, of 0.5 J
  EXPECT_LT(worst_energy_rise, kEnergyTolerance);
}

}  // namespace
}  // namespace mbopt::multibody
