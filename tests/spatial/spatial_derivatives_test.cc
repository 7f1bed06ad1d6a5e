// The spatial system's Newton-matrix derivatives against difference
// quotients of the equations they differentiate, as the planar
// MultibodyDerivatives tests do: the constraints' curvature
// d(Phi_q^T w)/dq for every joint kind and both drivers, the velocity
// constraints' Jacobian d(Phi_q v + Phi_t)/dq, the mass matrix's
// d(M(q) a)/dq, the force Jacobians (Euler parameters' velocity terms,
// linear and tabulated springs, point forces and torques in world and body
// axes, rotational spring-dampers on revolute and cylindrical joints, wound
// past a turn, and bushings at x-y-z angles of 40-70 deg), the declared
// pattern, the same through combined rows (redundant joints), and the
// assembled GGL Newton matrix against the residual at non-zero
// accelerations: the whole state Jacobian.
#include <cmath>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "worker/multibody/ggl_residual.h"
#include "worker/spatial/euler_parameters.h"
#include "worker/spatial/redundant_constraints.h"
#include "worker/spatial/spatial_force_elements.h"
#include "worker/spatial/spatial_system.h"

namespace mbopt::spatial {
namespace {

using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

// Central differences with step 1e-6 on coordinates of order 1: truncation
// ~1e-12 times third derivatives of order 1, round-off ~1e-16 / 1e-6 times
// the values differenced (the normalization rows' scale 1e6 times that:
// they are compared relative to their size).
constexpr double kStep = 1e-6;
constexpr double kDifferenceTolerance = 1e-7;

Body Brick(const std::string& name, const Vector3d& position, const Matrix3d& orientation) {
  Body b;
  b.name = name;
  b.mass_kg = 2.0;
  b.inertia_kg_m2 << 0.05, 0.004, -0.002, 0.004, 0.08, 0.001, -0.002, 0.001, 0.11;
  b.position_m = position;
  b.orientation = orientation;
  return b;
}

Frame FrameOn(int body, const Vector3d& at, const Matrix3d& axes = Matrix3d::Identity()) {
  Frame f;
  f.body = body;
  f.position_m = at;
  f.axes = axes;
  return f;
}

// Two bodies joined by `kind`, one of them to ground by a spherical joint.
Model TwoBodies(Joint::Kind kind) {
  Model m;
  m.bodies.push_back(Brick("one", {0.1, 0.2, -0.3}, AxisAngle({1, 2, 3}, 0.7)));
  m.bodies.push_back(Brick("two", {0.5, -0.1, 0.2}, AxisAngle({-2, 1, 0.5}, 1.1)));
  m.joints.push_back({"anchor", Joint::Kind::kSpherical, FrameOn(kGround, {0, 0, 0.1}), FrameOn(0, {0.0, 0.1, 0.2})});
  m.joints.push_back({"between", kind, FrameOn(0, {0.2, -0.1, 0.05}, AxisAngle({0, 1, 1}, 0.4)),
                      FrameOn(1, {-0.1, 0.15, 0.0}, AxisAngle({1, 0, 1}, -0.3))});
  m.gravity_m_per_s2 = Vector3d(0.0, 0.0, -9.81);
  return m;
}

// A state off the unit sphere and off the constraints, with rates.
void GeneralState(const SpatialSystem& s, VectorXd* q, VectorXd* v) {
  *q = s.InitialGuess();
  *v = VectorXd::LinSpaced(q->size(), -0.7, 0.9);
  for (int i = 0; i < q->size(); ++i) (*q)[i] += 0.01 * std::sin(1.3 * i);
}

// The largest difference relative to max(1, the larger magnitude).
double RelativeDifference(const MatrixXd& a, const MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, std::max(a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff()));
}

// d(Phi_q^T w)/dq and d(Phi_q v + Phi_t)/dq at time t against central
// differences of Phi_q^T w and of Phi_q v + Phi_t, column by column.
void ExpectConstraintDerivatives(const multibody::ConstrainedSystem& s, const VectorXd& q, const VectorXd& v,
                                 double t) {
  const VectorXd w = VectorXd::LinSpaced(s.num_constraints(), 1.3, -0.8);
  MatrixXd curvature, velocity_q;
  ASSERT_EQ(s.ConstraintCurvature(t, q, w, &curvature), 0);
  ASSERT_EQ(s.VelocityConstraintJacobian(t, q, v, &velocity_q), 0);
  MatrixXd curvature_dq(q.size(), q.size()), velocity_dq(s.num_constraints(), q.size());
  for (int k = 0; k < q.size(); ++k) {
    VectorXd plus = q, minus = q, phi_t_plus, phi_t_minus;
    plus[k] += kStep;
    minus[k] -= kStep;
    MatrixXd jac_plus, jac_minus;
    ASSERT_EQ(s.ConstraintJacobian(t, plus, &jac_plus), 0);
    ASSERT_EQ(s.ConstraintJacobian(t, minus, &jac_minus), 0);
    ASSERT_EQ(s.ConstraintTimeDerivative(t, plus, &phi_t_plus), 0);
    ASSERT_EQ(s.ConstraintTimeDerivative(t, minus, &phi_t_minus), 0);
    curvature_dq.col(k) = (jac_plus - jac_minus).transpose() * w / (2 * kStep);
    velocity_dq.col(k) = ((jac_plus - jac_minus) * v + phi_t_plus - phi_t_minus) / (2 * kStep);
  }
  EXPECT_LT(RelativeDifference(curvature, curvature_dq), kDifferenceTolerance);
  EXPECT_LT(RelativeDifference(velocity_q, velocity_dq), kDifferenceTolerance);
  EXPECT_LT((curvature - curvature.transpose()).cwiseAbs().maxCoeff(), 1e-9);  // symmetric
  // Not a trivial match: the joints' curvature is there.
  EXPECT_GT(curvature.bottomRightCorner(7, 7).cwiseAbs().maxCoeff(), 1e-3);
}

class EveryJointDerivatives : public ::testing::TestWithParam<Joint::Kind> {};

TEST_P(EveryJointDerivatives, MatchDifferenceQuotients) {
  const Model model = TwoBodies(GetParam());
  ASSERT_TRUE(model.Validate().ok());
  const SpatialSystem s(model);
  EXPECT_TRUE(s.has_analytic_derivatives());
  VectorXd q, v;
  GeneralState(s, &q, &v);
  ExpectConstraintDerivatives(s, q, v, 0.0);
}

INSTANTIATE_TEST_SUITE_P(SpatialDerivatives, EveryJointDerivatives,
                         ::testing::Values(Joint::Kind::kSpherical, Joint::Kind::kRevolute, Joint::Kind::kUniversal,
                                           Joint::Kind::kFixed, Joint::Kind::kPrismatic, Joint::Kind::kCylindrical,
                                           Joint::Kind::kPlanar, Joint::Kind::kPointOnLine,
                                           Joint::Kind::kPointOnPlane),
                         [](const ::testing::TestParamInfo<Joint::Kind>& info) {
                           std::string name = JointKindName(info.param);
                           for (char& c : name) {
                             if (c == ' ') c = '_';
                           }
                           return name;
                         });

// A cylindrical joint driven in its angle (harmonic: Phi_t depends on q)
// and in its slide.
Model DrivenCylinder() {
  Model model = TwoBodies(Joint::Kind::kCylindrical);
  Driver angle;
  angle.joint = 1;
  angle.profile.kind = multibody::Profile::Kind::kHarmonic;
  angle.profile.start = 0.3;
  angle.profile.amplitude = 0.8;
  angle.profile.angular_frequency_rad_per_s = 3.0;
  angle.profile.phase_rad = 0.2;
  Driver slide;
  slide.joint = 1;
  slide.slide = true;
  slide.profile.kind = multibody::Profile::Kind::kHarmonic;
  slide.profile.start = 0.05;
  slide.profile.amplitude = 0.1;
  slide.profile.angular_frequency_rad_per_s = 4.0;
  slide.profile.phase_rad = 0.3;
  model.drivers = {angle, slide};
  return model;
}

TEST(SpatialDerivatives, DriversMatchDifferenceQuotients) {
  const Model model = DrivenCylinder();
  ASSERT_TRUE(model.Validate().ok()) << model.Validate();
  const SpatialSystem s(model);
  VectorXd q, v;
  GeneralState(s, &q, &v);
  ExpectConstraintDerivatives(s, q, v, 0.4);
}

// Rows replaced by combinations T Phi (redundant joints): the derivatives
// pass through T.
TEST(SpatialDerivatives, CombinedRowsMatchDifferenceQuotients) {
  const Model model = DrivenCylinder();
  const SpatialSystem s(model);
  const int m = s.num_constraints();
  MatrixXd combination(m - 2, m);
  for (int i = 0; i < m - 2; ++i) {
    for (int k = 0; k < m; ++k) combination(i, k) = std::cos(0.7 * i + 1.9 * k) * (k >= i ? 1.0 : 0.0);
  }
  const CombinedConstraintSystem combined(s, combination);
  EXPECT_TRUE(combined.has_analytic_derivatives());
  VectorXd q, v;
  GeneralState(s, &q, &v);
  ExpectConstraintDerivatives(combined, q, v, 0.4);
  multibody::ConstrainedSystem::Pattern coupling, rows;
  combined.DerivativePattern(&coupling, &rows);
  MatrixXd phi_q, velocity_q;
  ASSERT_EQ(combined.ConstraintJacobian(0.4, q, &phi_q), 0);
  ASSERT_EQ(combined.VelocityConstraintJacobian(0.4, q, v, &velocity_q), 0);
  EXPECT_FALSE(((phi_q.array() != 0.0) && !rows).any());
  EXPECT_FALSE(((velocity_q.array() != 0.0) && !rows).any());
}

// Every force element on the two bodies: a damped spring, a follower
// force, a body-axes torque, a rotational spring-damper on the revolute
// joint and a bushing.
Model ForcedPair() {
  Model m = TwoBodies(Joint::Kind::kRevolute);
  SpringDamper spring;
  spring.name = "spring";
  spring.a = {kGround, {0.3, 0.4, 0.5}};
  spring.b = {1, {0.05, -0.02, 0.1}};
  spring.stiffness_n_per_m = 120.0;
  spring.free_length_m = 0.2;
  spring.damping_n_s_per_m = 3.0;
  m.springs.push_back(spring);
  PointForce force;
  force.name = "push";
  force.at = {0, {0.1, 0.0, -0.05}};
  force.force_n = {1.0, -2.0, 0.5};
  force.body_axes = true;
  m.point_forces.push_back(force);
  BodyTorque torque;
  torque.name = "twist";
  torque.body = 1;
  torque.torque_n_m = {0.3, 0.1, -0.2};
  torque.body_axes = true;
  m.torques.push_back(torque);
  RotationalSpringDamper rotational;
  rotational.name = "hinge";
  rotational.joint = 1;
  rotational.stiffness_n_m_per_rad = 5.0;
  rotational.damping_n_m_s_per_rad = 0.4;
  rotational.free_angle_rad = 0.1;
  m.rotational_springs.push_back(rotational);
  Bushing bushing;
  bushing.name = "mount";
  bushing.a = FrameOn(kGround, {0.4, -0.2, 0.1});
  bushing.b = FrameOn(0, {-0.1, 0.05, 0.0}, AxisAngle({1, 1, 0}, 0.2));
  bushing.stiffness_n_per_m = {200, 300, 400};
  bushing.damping_n_s_per_m = {2, 3, 4};
  bushing.rotational_stiffness_n_m_per_rad = {10, 20, 30};
  bushing.rotational_damping_n_m_s_per_rad = {0.1, 0.2, 0.3};
  m.bushings.push_back(bushing);
  return m;
}

// The elements with analytic Jacobians, each kind in both variants: a
// damped linear spring with an actuator force between the bodies, a spring
// from ground with tabulated deflection and velocity curves, point forces
// in world and body axes (one with a time factor) and torques in world and
// body axes.
Model AnalyticForcedPair() {
  Model m = TwoBodies(Joint::Kind::kRevolute);
  SpringDamper linear;
  linear.name = "linear";
  linear.a = {0, {0.1, -0.2, 0.05}};
  linear.b = {1, {0.05, -0.02, 0.1}};
  linear.stiffness_n_per_m = 120.0;
  linear.free_length_m = 0.2;
  linear.damping_n_s_per_m = 3.0;
  linear.actuator_force_n = 4.0;
  m.springs.push_back(linear);
  SpringDamper tabulated;
  tabulated.name = "tabulated";
  tabulated.a = {kGround, {0.3, 0.4, 0.5}};
  tabulated.b = {1, {-0.1, 0.08, 0.02}};
  tabulated.free_length_m = 0.3;
  tabulated.deflection_curve.x = {-2.0, -0.5, 3.0};
  tabulated.deflection_curve.y = {-300.0, -40.0, 500.0};
  tabulated.velocity_curve.x = {-20.0, -3.0, 20.0};
  tabulated.velocity_curve.y = {-90.0, -6.0, 60.0};
  m.springs.push_back(tabulated);
  PointForce world;
  world.name = "world";
  world.at = {1, {0.1, 0.2, -0.05}};
  world.force_n = {2.0, -1.0, 3.0};
  world.factor = multibody::Profile{};
  world.factor->kind = multibody::Profile::Kind::kHarmonic;
  world.factor->start = 0.5;
  world.factor->amplitude = 0.8;
  world.factor->angular_frequency_rad_per_s = 3.0;
  m.point_forces.push_back(world);
  PointForce follower;
  follower.name = "follower";
  follower.at = {0, {0.1, 0.0, -0.05}};
  follower.force_n = {1.0, -2.0, 0.5};
  follower.body_axes = true;
  m.point_forces.push_back(follower);
  BodyTorque body_torque;
  body_torque.name = "twist";
  body_torque.body = 1;
  body_torque.torque_n_m = {0.3, 0.1, -0.2};
  body_torque.body_axes = true;
  m.torques.push_back(body_torque);
  BodyTorque world_torque;
  world_torque.name = "turn";
  world_torque.body = 0;
  world_torque.torque_n_m = {-0.4, 0.2, 0.6};
  m.torques.push_back(world_torque);
  return m;
}

// dQ/dq and dQ/dv against central differences of AppliedForces: with only
// gravity (the Euler parameters' velocity terms alone) and with every
// force element. Every model has the exact state Jacobian now (before, one
// with a rotational spring or a bushing had not).
void ExpectForceJacobians(const Model& model) {
  ASSERT_TRUE(model.Validate().ok()) << model.Validate();
  const SpatialSystem s(model);
  EXPECT_TRUE(s.has_exact_state_jacobian());
  VectorXd q, v;
  GeneralState(s, &q, &v);
  const double t = 0.25;
  MatrixXd q_q, q_v;
  ASSERT_EQ(s.ForceJacobians(t, q, v, &q_q, &q_v), 0);
  MatrixXd q_q_dq(q.size(), q.size()), q_v_dq(q.size(), q.size());
  for (int k = 0; k < q.size(); ++k) {
    VectorXd plus = q, minus = q, f_plus, f_minus;
    plus[k] += kStep;
    minus[k] -= kStep;
    ASSERT_EQ(s.AppliedForces(t, plus, v, &f_plus), 0);
    ASSERT_EQ(s.AppliedForces(t, minus, v, &f_minus), 0);
    q_q_dq.col(k) = (f_plus - f_minus) / (2 * kStep);
    plus = v;
    minus = v;
    plus[k] += kStep;
    minus[k] -= kStep;
    ASSERT_EQ(s.AppliedForces(t, q, plus, &f_plus), 0);
    ASSERT_EQ(s.AppliedForces(t, q, minus, &f_minus), 0);
    q_v_dq.col(k) = (f_plus - f_minus) / (2 * kStep);
  }
  EXPECT_LT(RelativeDifference(q_q, q_q_dq), kDifferenceTolerance);
  EXPECT_LT(RelativeDifference(q_v, q_v_dq), kDifferenceTolerance);
  EXPECT_GT(q_v.cwiseAbs().maxCoeff(), 1e-2);  // the velocity terms are there
}

TEST(SpatialDerivatives, VelocityTermsMatchDifferenceQuotients) { ExpectForceJacobians(TwoBodies(Joint::Kind::kUniversal)); }

// Every element, the rotational spring and the bushing among them (before,
// those two were differenced and the system had no exact state Jacobian).
TEST(SpatialDerivatives, ForceElementsMatchDifferenceQuotients) { ExpectForceJacobians(ForcedPair()); }

// Rx(x) Ry(y) Rz(z), the angles in degrees.
Matrix3d XyzRotation(double x_deg, double y_deg, double z_deg) {
  const double to_rad = std::numbers::pi / 180.0;
  return AxisAngle({1, 0, 0}, x_deg * to_rad) * AxisAngle({0, 1, 0}, y_deg * to_rad) *
         AxisAngle({0, 0, 1}, z_deg * to_rad);
}

// Two bushings at large rotations, frames off the centres of mass,
// stiffnesses and dampings different on every axis: ground to body one
// with frames at x-y-z angles (50, -40, 65) deg, body one to body two at
// (40, 70, -50) deg (a middle angle of 70 deg, 1 / cos = 2.9).
Model BushedPair() {
  Model m = TwoBodies(Joint::Kind::kRevolute);
  const Matrix3d one = m.bodies[0].orientation, two = m.bodies[1].orientation;
  const Matrix3d ground_axes = AxisAngle({0, 0, 1}, 0.3), between_axes = AxisAngle({1, 0, 1}, 0.5);
  // Bushing{name, a, b, stiffness, damping, rotational stiffness and damping}.
  m.bushings.push_back(Bushing{"mount", FrameOn(kGround, {0.4, -0.2, 0.1}, ground_axes),
                               FrameOn(0, {-0.1, 0.05, 0.02}, one.transpose() * ground_axes * XyzRotation(50, -40, 65)),
                               {200, 300, 400}, {2, 3, 4}, {30, 60, 45}, {2, 5, 3}});
  m.bushings.push_back(
      Bushing{"link", FrameOn(0, {0.1, 0.1, -0.05}, between_axes),
              FrameOn(1, {-0.05, 0.1, 0.08}, two.transpose() * one * between_axes * XyzRotation(40, 70, -50)),
              {500, 100, 250}, {1, 6, 3}, {50, 20, 35}, {4, 1, 2.5}});
  return m;
}

TEST(SpatialDerivatives, BushingsAtLargeRotationsMatchDifferenceQuotients) {
  const Model model = BushedPair();
  ExpectForceJacobians(model);
  // The angles are what they were set to, give or take the general
  // state's offsets.
  const SpatialSystem s(model);
  VectorXd q, v;
  GeneralState(s, &q, &v);
  for (int b = 0; b < 2; ++b) {
    const Vector3d angles_deg = BushingLoadOf(model, b, q, v).angles_rad * 180.0 / std::numbers::pi;
    EXPECT_GT(angles_deg.cwiseAbs().minCoeff(), 35.0) << angles_deg.transpose();
    EXPECT_LT(angles_deg.cwiseAbs().maxCoeff(), 75.0) << angles_deg.transpose();
  }
}

// A rotational spring-damper on the joint between the bodies, wound past a
// turn (theta - theta0 near 9 rad: a torque of 60 N m or so, so its
// curvature term, torque times the angle's Hessian, counts).
Model WoundSpringPair(Joint::Kind kind) {
  Model m = TwoBodies(kind);
  RotationalSpringDamper wound;
  wound.name = "wound";
  wound.joint = 1;
  wound.stiffness_n_m_per_rad = 7.0;
  wound.damping_n_m_s_per_rad = 0.6;
  wound.free_angle_rad = -9.0;
  m.rotational_springs.push_back(wound);
  return m;
}

TEST(SpatialDerivatives, RotationalSpringsMatchDifferenceQuotients) {
  for (const Joint::Kind kind : {Joint::Kind::kRevolute, Joint::Kind::kCylindrical}) {
    SCOPED_TRACE(JointKindName(kind));
    const Model model = WoundSpringPair(kind);
    ExpectForceJacobians(model);
    const SpatialSystem s(model);
    VectorXd q, v;
    GeneralState(s, &q, &v);
    EXPECT_GT(std::abs(s.RotationalSpringTorque(0, q, v)), 40.0);
  }
}

// A bushing past its middle-angle limit: no Jacobian outside a continued
// scope, as no force.
TEST(SpatialDerivatives, BushingPastItsAngleLimitHasNoJacobian) {
  Model model = BushedPair();
  const Matrix3d one = model.bodies[0].orientation;
  model.bushings[0].b.axes = one.transpose() * model.bushings[0].a.axes * XyzRotation(10, 87, 20);
  const SpatialSystem s(model);
  const VectorXd q = s.InitialGuess(), v = VectorXd::Zero(q.size());
  VectorXd forces;
  MatrixXd q_q, q_v;
  EXPECT_NE(s.AppliedForces(0.0, q, v, &forces), 0);
  EXPECT_NE(s.ForceJacobians(0.0, q, v, &q_q, &q_v), 0);
}

TEST(SpatialDerivatives, AnalyticElementJacobiansMatchDifferenceQuotients) {
  const Model model = AnalyticForcedPair();
  ExpectForceJacobians(model);
  const SpatialSystem s(model);
  // The tabulated spring's state lies inside its curves' middle segments
  // (not across a breakpoint, where the difference would straddle two
  // slopes) and well away from the linear coefficients.
  VectorXd q, v;
  GeneralState(s, &q, &v);
  const Vector3d d = s.PointPosition(model.springs[1].b, q) - s.PointPosition(model.springs[1].a, q);
  const double rate = d.normalized().dot(s.PointVelocity(model.springs[1].b, q, v));
  EXPECT_GT(d.norm() - 0.3, -0.5 + 1e-3);
  EXPECT_LT(d.norm() - 0.3, 3.0 - 1e-3);
  EXPECT_GT(rate, -3.0 + 1e-3);
  EXPECT_LT(rate, 20.0 - 1e-3);
}

// d(M(q) a)/dq against central differences of M(q) a, off the unit sphere.
TEST(SpatialDerivatives, MassMatrixDerivativeMatchesDifferenceQuotients) {
  const Model model = TwoBodies(Joint::Kind::kUniversal);
  const SpatialSystem s(model);
  VectorXd q, v;
  GeneralState(s, &q, &v);
  const VectorXd a = VectorXd::LinSpaced(q.size(), 2.0, -3.0);
  MatrixXd jacobian;
  ASSERT_EQ(s.MassTimesAccelerationJacobian(q, a, &jacobian), 0);
  MatrixXd difference(q.size(), q.size());
  for (int k = 0; k < q.size(); ++k) {
    VectorXd plus = q, minus = q;
    plus[k] += kStep;
    minus[k] -= kStep;
    MatrixXd m_plus, m_minus;
    ASSERT_EQ(s.MassMatrix(plus, &m_plus), 0);
    ASSERT_EQ(s.MassMatrix(minus, &m_minus), 0);
    difference.col(k) = (m_plus - m_minus) * a / (2 * kStep);
  }
  EXPECT_LT(RelativeDifference(jacobian, difference), kDifferenceTolerance);
  EXPECT_GT(jacobian.cwiseAbs().maxCoeff(), 1e-2);  // not trivially zero
}

// The pattern the sparse Newton matrix is built on holds every non-zero
// entry of the derivatives: three bodies in a chain, the first and the
// last not coupled.
TEST(SpatialDerivatives, PatternHoldsEveryNonZero) {
  Model model = ForcedPair();
  model.bodies.push_back(Brick("three", {0.9, 0.3, -0.1}, AxisAngle({0, 0, 1}, 0.5)));
  model.joints.push_back({"end", Joint::Kind::kUniversal, FrameOn(1, {0.2, 0.1, 0.0}), FrameOn(2, {-0.2, 0.0, 0.1})});
  ASSERT_TRUE(model.Validate().ok()) << model.Validate();
  const SpatialSystem s(model);
  VectorXd q, v;
  GeneralState(s, &q, &v);
  const VectorXd w = VectorXd::LinSpaced(s.num_constraints(), 1.3, -0.8);
  MatrixXd mass, phi_q, curvature, velocity_q, q_q, q_v;
  ASSERT_EQ(s.MassMatrix(q, &mass), 0);
  ASSERT_EQ(s.ConstraintJacobian(0.1, q, &phi_q), 0);
  ASSERT_EQ(s.ConstraintCurvature(0.1, q, w, &curvature), 0);
  ASSERT_EQ(s.VelocityConstraintJacobian(0.1, q, v, &velocity_q), 0);
  ASSERT_EQ(s.ForceJacobians(0.1, q, v, &q_q, &q_v), 0);
  multibody::ConstrainedSystem::Pattern coupling, rows;
  s.DerivativePattern(&coupling, &rows);
  for (const MatrixXd* m : {&mass, &curvature, &q_q, &q_v}) {
    EXPECT_FALSE(((m->array() != 0.0) && !coupling).any());
  }
  for (const MatrixXd* m : {&phi_q, &velocity_q}) EXPECT_FALSE(((m->array() != 0.0) && !rows).any());
  EXPECT_FALSE((coupling.block<7, 7>(0, 14).any()));  // bodies one and three share no element
}

// The GGL Newton matrix assembled from these derivatives against
// difference quotients of the residual, in a moving state with non-zero
// accelerations y' (so d(M(q) v')/dq counts), on the driven cylinder and
// with every element that has an analytic Jacobian.
void ExpectNewtonMatrixMatchesTheResidual(const Model& model) {
  ASSERT_TRUE(model.Validate().ok()) << model.Validate();
  const SpatialSystem s(model);
  EXPECT_TRUE(s.has_exact_state_jacobian());
  const int n = s.num_coordinates(), m = s.num_constraints(), size = 2 * n + 2 * m;
  VectorXd q, v;
  GeneralState(s, &q, &v);
  VectorXd y(size), y_dot = VectorXd::Zero(size);
  y << q, v, VectorXd::LinSpaced(m, 0.5, -0.4), VectorXd::LinSpaced(m, -0.02, 0.03);
  y_dot.head(n) = v;
  y_dot.segment(n, n) = VectorXd::LinSpaced(n, 3.0, -2.5);
  const double t = 0.4, cj = 250.0;
  multibody::GglWorkspace work;
  MatrixXd newton;
  ASSERT_EQ(multibody::GglNewtonMatrix(s, t, cj, y, y_dot, &work, &newton), 0);
  MatrixXd difference(size, size);
  VectorXd r_plus(size), r_minus(size);
  for (int k = 0; k < size; ++k) {
    VectorXd yp = y, ym = y, ydp = y_dot, ydm = y_dot;
    yp[k] += kStep;
    ym[k] -= kStep;
    // F(y + h e_k, y' + cj h e_k): dF/dy + cj dF/dy'.
    ydp[k] += cj * kStep;
    ydm[k] -= cj * kStep;
    ASSERT_EQ(multibody::GglResidual(s, t, yp, ydp, &work, r_plus), 0);
    ASSERT_EQ(multibody::GglResidual(s, t, ym, ydm, &work, r_minus), 0);
    difference.col(k) = (r_plus - r_minus) / (2 * kStep);
  }
  // Rows of the normalization constraints are scaled by 1e6: relative.
  for (int row = 0; row < size; ++row) {
    const double scale = std::max(1.0, newton.row(row).cwiseAbs().maxCoeff());
    EXPECT_LT((newton.row(row) - difference.row(row)).cwiseAbs().maxCoeff() / scale, kDifferenceTolerance)
        << "row " << row;
  }
}

TEST(SpatialDerivatives, NewtonMatrixMatchesTheResidual) { ExpectNewtonMatrixMatchesTheResidual(DrivenCylinder()); }

TEST(SpatialDerivatives, NewtonMatrixWithForceElementsMatchesTheResidual) {
  Model model = AnalyticForcedPair();
  model.drivers = DrivenCylinder().drivers;
  model.joints[1].kind = Joint::Kind::kCylindrical;
  ExpectNewtonMatrixMatchesTheResidual(model);
}

TEST(SpatialDerivatives, NewtonMatrixWithBushingsAndRotationalSpringMatchesTheResidual) {
  Model model = BushedPair();
  model.joints[1].kind = Joint::Kind::kCylindrical;
  model.rotational_springs = WoundSpringPair(Joint::Kind::kCylindrical).rotational_springs;
  ExpectNewtonMatrixMatchesTheResidual(model);
}

}  // namespace
}  // namespace mbopt::spatial
