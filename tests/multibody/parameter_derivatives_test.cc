// The exact parameter partials of the multibody equations
// (parameter_derivatives.h) against central differences of the equations of
// models compiled at p +- h, one parameter kind at a time; the geometry's
// parameters, which have none, against the same differences through the
// fallback; and forward sensitivities formed with them against SUNDIALS'
// published answer, without a residual of the varied models during the
// integration.
//
// The coefficients enter linearly, so the differences (step 1e-3 of the
// value) carry only round-off, about 1e-16 |F| / 1e-3: compared at 1e-9 of
// the largest partial.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/multibody/mechanisms.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/ggl_residual.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/parameter_derivatives.h"

namespace mbopt::multibody {
namespace {

using Eigen::VectorXd;
using testing::At;
using testing::Bar;
using testing::Revolute;

// The parameters of TwoBarModel, in order.
enum Parameter {
  kMass, kInertia, kStiffness, kDamping, kActuator, kRotationalStiffness, kRotationalDamping, kForce, kTorque,
  kMarkerX, kFreeLength, kCount
};
const char* const kNames[] = {"mass", "inertia", "stiffness", "damping", "actuator force", "rotational stiffness",
                              "rotational damping", "point force", "torque", "marker x", "free length"};

std::vector<double> Nominal() { return {2.0, 0.3, 800.0, 12.0, 15.0, 40.0, 0.7, 25.0, 3.0, 0.35, 0.25}; }

// Two bars pinned in a chain to ground under gravity, a spring-damper
// between them, a rotational spring-damper at the second pin, a point force
// and a torque: every coefficient kind the derivative models cover, plus
// two geometry numbers they do not.
Model TwoBarModel(const std::vector<double>& p) {
  Model m;
  m.bodies.push_back(Bar("upper", 1.5, 0.8, {0.4, 0.0}, 0.0));
  m.bodies.push_back(Bar("lower", p[kMass], 0.6, {1.1, 0.0}, 0.0));
  m.bodies[1].inertia_kg_m2 = p[kInertia];
  m.joints.push_back(Revolute("root", At(kGround, 0.0), At(0, -0.4)));
  m.joints.push_back(Revolute("knee", At(0, 0.4), At(1, -0.3)));
  SpringDamper s;
  s.name = "strut";
  s.a = At(0, 0.0, 0.1);
  s.b = At(1, p[kMarkerX] - 0.3, 0.05);
  s.free_length_m = p[kFreeLength];
  s.stiffness_n_per_m = p[kStiffness];
  s.damping_n_s_per_m = p[kDamping];
  s.actuator_force_n = p[kActuator];
  m.springs.push_back(s);
  m.rotational_springs.push_back(RotationalSpringDamper{"knee spring", 1, p[kRotationalStiffness],
                                                        p[kRotationalDamping], 0.2});
  m.point_forces.push_back(PointForce{At(1, 0.3), Eigen::Vector2d(0.6, -0.8) * p[kForce], std::nullopt});
  m.torques.push_back(BodyTorque{0, p[kTorque], std::nullopt});
  m.gravity_m_per_s2 = Eigen::Vector2d(0.0, -9.81);
  return m;
}

// A state off equilibrium and off the constraints: every row of the
// residual is at work.
struct State {
  VectorXd y, y_dot;
};
State SomeState(const Mechanism& mechanism) {
  const int n = mechanism.num_coordinates(), m = mechanism.num_constraints(), size = 2 * n + 2 * m;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  State s;
  s.y = VectorXd::NullaryExpr(size, [&]() { return uniform(random); });
  s.y_dot = VectorXd::NullaryExpr(size, [&]() { return uniform(random); });
  s.y.head(n) = mechanism.InitialGuess() + 0.05 * s.y.head(n);
  return s;
}

struct Variants {
  Model plus, minus;
  double step = 0.0;
};
Variants Vary(int k, double relative_step) {
  Variants v;
  std::vector<double> up = Nominal(), down = Nominal();
  v.step = relative_step * std::abs(up[static_cast<size_t>(k)]);
  up[static_cast<size_t>(k)] += v.step;
  down[static_cast<size_t>(k)] -= v.step;
  v.plus = TwoBarModel(up);
  v.minus = TwoBarModel(down);
  return v;
}

// dF/dp by central differences of the GGL residual, at the test's step.
VectorXd DifferencedGgl(int k, const State& x) {
  const Variants v = Vary(k, 1e-3);
  const Mechanism plus(v.plus), minus(v.minus);
  GglWorkspace work;
  VectorXd r_plus(x.y.size()), r_minus(x.y.size());
  EXPECT_EQ(GglResidual(plus, 0.3, x.y, x.y_dot, &work, r_plus), 0);
  EXPECT_EQ(GglResidual(minus, 0.3, x.y, x.y_dot, &work, r_minus), 0);
  return (r_plus - r_minus) / (2.0 * v.step);
}

double Largest(const VectorXd& v) { return v.cwiseAbs().maxCoeff(); }

TEST(ParameterDerivatives, CoefficientsHaveExactPartialsOfTheMotionEquations) {
  const Model nominal = TwoBarModel(Nominal());
  const Mechanism mechanism(nominal);
  const State x = SomeState(mechanism);
  for (int k = 0; k < kCount; ++k) {
    // The integration's own step (1e-5), the reference's another.
    const Variants v = Vary(k, 1e-5);
    const std::unique_ptr<ParameterDerivativeModel> derivative =
        ParameterDerivativeModel::Of(nominal, v.plus, v.minus, v.step);
    if (k == kMarkerX || k == kFreeLength) {
      EXPECT_EQ(derivative, nullptr) << kNames[k] << " is geometry: no derivative model";
      continue;
    }
    ASSERT_NE(derivative, nullptr) << kNames[k];
    const Mechanism plus(v.plus), minus(v.minus);
    ParameterPerturbation dp{&plus, &minus, v.step, 1.0, &derivative->system()};
    GglWorkspace work;
    VectorXd exact(x.y.size());
    ASSERT_EQ(GglParameterDerivative(dp, 0.3, x.y, x.y_dot, &work, exact), 0) << kNames[k];
    const VectorXd reference = DifferencedGgl(k, x);
    ASSERT_GT(Largest(reference), 1e-3) << kNames[k] << " must enter the equations";
    EXPECT_LT(Largest(exact - reference), 1e-9 * Largest(reference))
        << kNames[k] << ": exact " << exact.transpose() << "\n differences " << reference.transpose();
  }
}

TEST(ParameterDerivatives, GeometryFallsBackToDifferencesOfTheEquationsAlone) {
  const Model nominal = TwoBarModel(Nominal());
  const Mechanism mechanism(nominal);
  const State x = SomeState(mechanism);
  for (const int k : {kMarkerX, kFreeLength}) {
    const Variants v = Vary(k, 1e-5);
    const Mechanism plus(v.plus), minus(v.minus);
    const ParameterPerturbation dp{&plus, &minus, v.step, 1.0, nullptr};
    GglWorkspace work;
    VectorXd partial(x.y.size());
    ASSERT_EQ(GglParameterDerivative(dp, 0.3, x.y, x.y_dot, &work, partial), 0);
    const VectorXd reference = DifferencedGgl(k, x);
    ASSERT_GT(Largest(reference), 1e-3) << kNames[k];
    // Not linear: the reference's step (1e-3) leaves truncation error.
    EXPECT_LT(Largest(partial - reference), 1e-5 * Largest(reference)) << kNames[k];
  }
}

// G = (Q(t, q, 0) - Phi_q^T lambda, Phi) of static equilibrium.
VectorXd StaticEquationsOf(const Mechanism& s, const VectorXd& q, const VectorXd& lambda) {
  VectorXd forces, phi;
  Eigen::MatrixXd phi_q;
  s.AppliedForces(0.3, q, VectorXd::Zero(q.size()), &forces);
  s.ConstraintJacobian(0.3, q, &phi_q);
  s.Constraints(0.3, q, &phi);
  VectorXd g(q.size() + phi.size());
  g << forces - phi_q.transpose() * lambda, phi;
  return g;
}

TEST(ParameterDerivatives, StaticEquationsHaveTheSamePartials) {
  const Model nominal = TwoBarModel(Nominal());
  const Mechanism mechanism(nominal);
  const State x = SomeState(mechanism);
  const int n = mechanism.num_coordinates(), m = mechanism.num_constraints();
  const VectorXd q = x.y.head(n), lambda = x.y.segment(2 * n, m);
  for (int k = 0; k < kCount; ++k) {
    const Variants v = Vary(k, 1e-5);
    const std::unique_ptr<ParameterDerivativeModel> derivative =
        ParameterDerivativeModel::Of(nominal, v.plus, v.minus, v.step);
    const Mechanism plus(v.plus), minus(v.minus);
    const ParameterPerturbation dp{&plus, &minus, v.step, 1.0,
                                   derivative != nullptr ? &derivative->system() : nullptr};
    VectorXd partial;
    ASSERT_EQ(StaticParameterDerivative(dp, 0.3, q, lambda, &partial), 0) << kNames[k];
    const Variants wide = Vary(k, 1e-3);
    const Mechanism wide_plus(wide.plus), wide_minus(wide.minus);
    const VectorXd reference =
        (StaticEquationsOf(wide_plus, q, lambda) - StaticEquationsOf(wide_minus, q, lambda)) / (2.0 * wide.step);
    // Inertia and damping do not act at rest (the mass does, by its weight).
    if (k == kInertia || k == kDamping || k == kRotationalDamping) {
      EXPECT_EQ(Largest(partial), 0.0) << kNames[k];
      continue;
    }
    ASSERT_GT(Largest(reference), 1e-3) << kNames[k];
    EXPECT_LT(Largest(partial - reference), (derivative != nullptr ? 1e-9 : 1e-5) * Largest(reference)) << kNames[k];
  }
}

// SUNDIALS' slider-crank with the spring's stiffness and damping as
// parameters, now through their derivative models: the published dG/dp
// (tests/multibody/sensitivity_test.cc has the set-up), and the varied
// models are evaluated at the start only (their consistent accelerations),
// never in the sensitivity residuals.
TEST(ParameterDerivatives, ForwardSensitivitiesUseThePartialsAlone) {
  constexpr double k = 1.0, c = 1.0, step = 1e-5;
  const Model nominal = testing::SundialsSliderCrank(k, c);
  const Model k_plus = testing::SundialsSliderCrank(k + step, c), k_minus = testing::SundialsSliderCrank(k - step, c);
  const Model c_plus = testing::SundialsSliderCrank(k, c + step), c_minus = testing::SundialsSliderCrank(k, c - step);
  const std::unique_ptr<ParameterDerivativeModel> dk = ParameterDerivativeModel::Of(nominal, k_plus, k_minus, step);
  const std::unique_ptr<ParameterDerivativeModel> dc = ParameterDerivativeModel::Of(nominal, c_plus, c_minus, step);
  ASSERT_NE(dk, nullptr);
  ASSERT_NE(dc, nullptr);
  const Mechanism m(nominal), mkp(k_plus), mkm(k_minus), mcp(c_plus), mcm(c_minus);
  const Assembly assembled = Assemble(m, 0.0);
  ASSERT_TRUE(assembled.failure.ok()) << assembled.failure.reason;
  ForwardSensitivityInput input;
  input.parameters = {ParameterPerturbation{&mkp, &mkm, step, 1.0, &dk->system()},
                      ParameterPerturbation{&mcp, &mcm, step, 1.0, &dc->system()}};
  input.q0.assign(2, VectorXd::Zero(m.num_coordinates()));
  input.v0.assign(2, VectorXd::Zero(m.num_coordinates()));
  ForwardDynamicsOptions options;
  options.relative_tolerance = 1e-6;
  options.absolute_tolerance = 1e-7;
  std::vector<double> times;
  for (int i = 0; i <= 10000; ++i) times.push_back(10.0 * i / 10000);
  std::vector<double> d_energy_dk, d_energy_dc;
  Eigen::MatrixXd mass;
  ForwardDynamicsCounters counters;
  const spec::AnalysisFailure f = IntegrateForward(
      m, 0.0, assembled.q, assembled.v, times, options,
      [&](const MotionSample& s) {
        m.MassMatrix(s.q, &mass);
        d_energy_dk.push_back(s.v.dot(mass * s.sensitivities[0].v));
        d_energy_dc.push_back(s.v.dot(mass * s.sensitivities[1].v));
        return spec::AnalysisFailure::Ok();
      },
      &counters, &input);
  ASSERT_TRUE(f.ok()) << f.reason;
  auto simpson = [&](const std::vector<double>& y) {
    const double h = times[1] - times[0];
    double sum = y.front() + y.back();
    for (size_t i = 1; i + 1 < y.size(); ++i) sum += (i % 2 == 1 ? 4.0 : 2.0) * y[i];
    return sum * h / 3.0;
  };
  EXPECT_NEAR(simpson(d_energy_dk), 0.33346, 5e-5);
  EXPECT_NEAR(simpson(d_energy_dc), -0.36375, 5e-5);
  for (const Mechanism* variant : {&mkp, &mkm, &mcp, &mcm}) {
    EXPECT_EQ(variant->counters().force_evaluations, 1) << "one consistent start per variant";
  }
  EXPECT_GT(dk->system().counters().force_evaluations, counters.steps) << "the partials, every step";
}

}  // namespace
}  // namespace mbopt::multibody
