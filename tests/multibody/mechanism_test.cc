// The equations of a mechanism: the constraint Jacobian and the acceleration
// right-hand side gamma of every joint and driver kind against central
// differences, and forces that exist only where declared.
#include "worker/multibody/mechanism.h"

#include <random>

#include <gtest/gtest.h>

#include "tests/multibody/mechanisms.h"

namespace mbopt::multibody {
namespace {

using testing::At;

// Every joint kind and both driver kinds in one (over-constrained) model: the
// rows are checked one by one, consistency of the whole does not matter.
Model EveryKind() {
  Model m = testing::SliderCrank(0.3, 1.0, 2.0);
  Joint fixed;
  fixed.name = "weld";
  fixed.kind = JointKind::kFixed;
  fixed.a = At(1, 0.1, 0.05);
  fixed.b = At(2, -0.2, 0.1);
  m.joints.push_back(fixed);
  Joint slot;
  slot.name = "slot";
  slot.kind = JointKind::kPointOnLine;
  slot.axis_angle_rad = 0.4;
  slot.a = At(0, 0.05, -0.02);
  slot.b = At(1, 0.3, 0.01);
  m.joints.push_back(slot);
  Joint prismatic;
  prismatic.name = "slide2";
  prismatic.kind = JointKind::kPrismatic;
  prismatic.axis_angle_rad = -0.7;
  prismatic.a = At(1, 0.2, 0.03);
  prismatic.b = At(0, -0.1, 0.04);
  m.joints.push_back(prismatic);
  Driver harmonic;
  harmonic.joint = static_cast<int>(m.joints.size()) - 1;
  harmonic.profile.kind = Profile::Kind::kHarmonic;
  harmonic.profile.amplitude = 0.1;
  harmonic.profile.angular_frequency_rad_per_s = 3.0;
  harmonic.profile.phase_rad = 0.2;
  m.drivers.push_back(harmonic);
  Driver polynomial;
  polynomial.joint = 1;
  polynomial.profile.kind = Profile::Kind::kPolynomial;
  polynomial.profile.coefficients = {0.1, -0.4, 0.3, 0.05};
  m.drivers.push_back(polynomial);
  return m;
}

// Central differences of smooth functions of order 1 with steps of 1e-6 are
// accurate to about 1e-9; the analytic rows must agree to that.
constexpr double kStep = 1e-6;
constexpr double kAgreement = 1e-7;

TEST(Mechanism, ConstraintJacobianMatchesCentralDifferences) {
  const Model model = EveryKind();
  ASSERT_TRUE(model.Validate().ok());
  const Mechanism m(model);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd q(m.num_coordinates());
    for (Eigen::Index i = 0; i < q.size(); ++i) q[i] = u(rng);
    const double t = 0.3 + trial;
    Eigen::MatrixXd jac;
    m.ConstraintJacobian(t, q, &jac);
    for (Eigen::Index i = 0; i < q.size(); ++i) {
      Eigen::VectorXd plus = q, minus = q, phi_plus, phi_minus;
      plus[i] += kStep;
      minus[i] -= kStep;
      m.Constraints(t, plus, &phi_plus);
      m.Constraints(t, minus, &phi_minus);
      const Eigen::VectorXd column = (phi_plus - phi_minus) / (2 * kStep);
      EXPECT_LT((jac.col(i) - column).cwiseAbs().maxCoeff(), kAgreement) << "coordinate " << i;
    }
    // Phi_t by differences in time.
    Eigen::VectorXd phi_t, phi_plus, phi_minus;
    m.ConstraintTimeDerivative(t, q, &phi_t);
    m.Constraints(t + kStep, q, &phi_plus);
    m.Constraints(t - kStep, q, &phi_minus);
    EXPECT_LT((phi_t - (phi_plus - phi_minus) / (2 * kStep)).cwiseAbs().maxCoeff(), kAgreement);
  }
}

// Along a path q(s) = q + s v, t(s) = t + s: d^2 Phi / ds^2 = Phi_q q'' -
// gamma with q'' = 0 here, so gamma = -d^2 Phi/ds^2 (second differences).
TEST(Mechanism, AccelerationRightSideIsMinusTheSecondDerivativeAlongAPath) {
  const Model model = EveryKind();
  const Mechanism m(model);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  constexpr double kSecondStep = 1e-4;           // second differences: error ~ h^2 + eps / h^2
  constexpr double kSecondAgreement = 1e-5;
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd q(m.num_coordinates()), v(m.num_coordinates());
    for (Eigen::Index i = 0; i < q.size(); ++i) {
      q[i] = u(rng);
      v[i] = u(rng);
    }
    const double t = 0.5 * trial;
    Eigen::VectorXd gamma, p0, pp, pm;
    m.AccelerationRightSide(t, q, v, &gamma);
    m.Constraints(t, q, &p0);
    m.Constraints(t + kSecondStep, q + kSecondStep * v, &pp);
    m.Constraints(t - kSecondStep, q - kSecondStep * v, &pm);
    const Eigen::VectorXd second = (pp - 2 * p0 + pm) / (kSecondStep * kSecondStep);
    EXPECT_LT((gamma + second).cwiseAbs().maxCoeff(), kSecondAgreement);
  }
}

TEST(Mechanism, UndeclaredGravityIsNeverEvaluated) {
  Model model = testing::Pendulum(1.0, 1.0, 0.3);
  model.gravity_m_per_s2.reset();
  const Mechanism m(model);
  Eigen::VectorXd forces;
  const Eigen::VectorXd q = m.InitialGuess(), v = Eigen::VectorXd::Zero(3);
  ASSERT_EQ(m.AppliedForces(0.0, q, v, &forces), 0);
  EXPECT_EQ(forces.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(m.counters().force_evaluations, 1);
  EXPECT_EQ(m.counters().gravity_evaluations, 0);
  const Model with_gravity = testing::Pendulum(1.0, 1.0, 0.3);
  const Mechanism with(with_gravity);
  with.AppliedForces(0.0, q, v, &forces);
  EXPECT_EQ(with.counters().gravity_evaluations, 1);
}

// A spring of stiffness k stretched by d from its free length pulls its ends
// together with k d; a damper adds c times the rate of lengthening.
TEST(Mechanism, SpringForceIsStiffnessTimesStretchPlusDamping) {
  Model model;
  Body b;
  b.name = "mass";
  b.mass_kg = 2.0;
  b.inertia_kg_m2 = 1.0;
  b.position_m = {1.5, 0.0};
  model.bodies.push_back(b);
  SpringDamper s;
  s.name = "spring";
  s.a = At(kGround, 0.0);
  s.b = At(0, 0.0);
  s.free_length_m = 1.0;
  s.stiffness_n_per_m = 100.0;
  s.damping_n_s_per_m = 3.0;
  model.springs.push_back(s);
  const Mechanism m(model);
  Eigen::VectorXd q = m.InitialGuess(), v(3), forces;
  v << 0.2, 0.0, 0.0;
  ASSERT_EQ(m.AppliedForces(0.0, q, v, &forces), 0);
  constexpr double kRoundOff = 1e-12;
  EXPECT_NEAR(forces[0], -(100.0 * 0.5 + 3.0 * 0.2), kRoundOff);
  EXPECT_NEAR(forces[1], 0.0, kRoundOff);
  EXPECT_NEAR(m.PotentialEnergy(q), 0.5 * 100.0 * 0.25, kRoundOff);
}

}  // namespace
}  // namespace mbopt::multibody
