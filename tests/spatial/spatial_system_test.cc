// The spatial kernel's equations checked against their definitions: every
// joint's Jacobian against difference quotients of its equations, gamma
// against difference quotients of Phi_q v along the motion, the mass matrix
// against the kinetic energy; the model's validation messages; assembly.
#include "worker/spatial/spatial_system.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "worker/spatial/euler_parameters.h"
#include "worker/spatial/spatial_assembly.h"

namespace mbopt::spatial {
namespace {

using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

// Central differences with step 1e-6 on coordinates of order 1: truncation
// error ~1e-12 times third derivatives of order 1, round-off ~1e-16 / 1e-6.
constexpr double kStep = 1e-6;
constexpr double kDifferenceTolerance = 1e-8;

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

// Two bodies joined by `kind` and one of them to ground by a spherical
// joint, in a general pose (the equations are evaluated away from the
// assembled configuration too: Jacobians must be exact everywhere).
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

// Differences in the rows' own units: the normalization rows without their
// scale (SpatialSystem::kNormRowScale), whose round-off it multiplies.
VectorXd Unscaled(const SpatialSystem& s, VectorXd rows) {
  rows.head(static_cast<int>(s.model().bodies.size())) /= SpatialSystem::kNormRowScale;
  return rows;
}

// A state off the unit sphere and off the constraints, with rates.
void GeneralState(const SpatialSystem& s, VectorXd* q, VectorXd* v) {
  *q = s.InitialGuess();
  *v = VectorXd::LinSpaced(q->size(), -0.7, 0.9);
  for (int i = 0; i < q->size(); ++i) (*q)[i] += 0.01 * std::sin(1.3 * i);
}

class EveryJoint : public ::testing::TestWithParam<Joint::Kind> {};

TEST_P(EveryJoint, JacobianIsTheDerivativeOfTheConstraints) {
  const Model model = TwoBodies(GetParam());
  ASSERT_TRUE(model.Validate().ok());
  const SpatialSystem s(model);
  VectorXd q, v;
  GeneralState(s, &q, &v);
  MatrixXd phi_q;
  ASSERT_EQ(s.ConstraintJacobian(0.0, q, &phi_q), 0);
  for (int j = 0; j < q.size(); ++j) {
    VectorXd plus = q, minus = q, phi_plus, phi_minus;
    plus[j] += kStep;
    minus[j] -= kStep;
    ASSERT_EQ(s.Constraints(0.0, plus, &phi_plus), 0);
    ASSERT_EQ(s.Constraints(0.0, minus, &phi_minus), 0);
    const VectorXd difference = (phi_plus - phi_minus) / (2 * kStep);
    EXPECT_LT(Unscaled(s, difference - phi_q.col(j)).cwiseAbs().maxCoeff(), kDifferenceTolerance) << "column " << j;
  }
}

// gamma = -(Phi_q v)_q v: along q(h) = q + h v, d(Phi_q v)/dh = -gamma.
TEST_P(EveryJoint, GammaIsMinusTheConvectiveDerivative) {
  const Model model = TwoBodies(GetParam());
  const SpatialSystem s(model);
  VectorXd q, v, gamma;
  GeneralState(s, &q, &v);
  ASSERT_EQ(s.AccelerationRightSide(0.0, q, v, &gamma), 0);
  MatrixXd plus, minus;
  ASSERT_EQ(s.ConstraintJacobian(0.0, q + kStep * v, &plus), 0);
  ASSERT_EQ(s.ConstraintJacobian(0.0, q - kStep * v, &minus), 0);
  const VectorXd difference = (plus - minus) * v / (2 * kStep);
  EXPECT_LT(Unscaled(s, difference + gamma).cwiseAbs().maxCoeff(), kDifferenceTolerance);
}

INSTANTIATE_TEST_SUITE_P(SpatialSystem, EveryJoint,
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

// A driven revolute joint: Phi_t and gamma against difference quotients in
// time of the driver's equation (its profile a harmonic, so Phi_tt and
// Phi_qt are not zero).
TEST(SpatialSystem, DriverRowsMatchTheirTimeDerivatives) {
  Model model = TwoBodies(Joint::Kind::kRevolute);
  Driver d;
  d.joint = 1;
  d.profile.kind = multibody::Profile::Kind::kHarmonic;
  d.profile.start = 0.3;
  d.profile.amplitude = 0.8;
  d.profile.angular_frequency_rad_per_s = 3.0;
  d.profile.phase_rad = 0.2;
  model.drivers.push_back(d);
  ASSERT_TRUE(model.Validate().ok());
  const SpatialSystem s(model);
  VectorXd q, v;
  GeneralState(s, &q, &v);
  const double t = 0.4;
  const int row = s.row_of_driver(0);
  VectorXd phi_t, gamma, phi_plus, phi_minus;
  ASSERT_EQ(s.ConstraintTimeDerivative(t, q, &phi_t), 0);
  ASSERT_EQ(s.Constraints(t + kStep, q, &phi_plus), 0);
  ASSERT_EQ(s.Constraints(t - kStep, q, &phi_minus), 0);
  EXPECT_NEAR(phi_t[row], (phi_plus[row] - phi_minus[row]) / (2 * kStep), kDifferenceTolerance);
  // Along (t + h, q + h v): d/dh (Phi_q v + Phi_t) = -gamma.
  ASSERT_EQ(s.AccelerationRightSide(t, q, v, &gamma), 0);
  auto rate = [&](double h) {
    MatrixXd phi_q;
    VectorXd phi_t_h;
    EXPECT_EQ(s.ConstraintJacobian(t + h, q + h * v, &phi_q), 0);
    EXPECT_EQ(s.ConstraintTimeDerivative(t + h, q + h * v, &phi_t_h), 0);
    return VectorXd(phi_q * v + phi_t_h);
  };
  const VectorXd difference = (rate(kStep) - rate(-kStep)) / (2 * kStep);
  EXPECT_NEAR(difference[row], -gamma[row], kDifferenceTolerance);
}

// A cylindrical joint driven in its angle and its slide: the slide
// driver's row (z_a.d - s(t)) has its Jacobian, Phi_t and gamma checked
// against difference quotients, and is zero where the slide is s(t).
TEST(SpatialSystem, SlideDriverRowMatchesItsDerivatives) {
  Model model = TwoBodies(Joint::Kind::kCylindrical);
  Driver angle;
  angle.joint = 1;
  angle.profile.kind = multibody::Profile::Kind::kConstantRate;
  angle.profile.rate = 2.0;
  Driver slide;
  slide.joint = 1;
  slide.slide = true;
  slide.profile.kind = multibody::Profile::Kind::kHarmonic;
  slide.profile.start = 0.05;
  slide.profile.amplitude = 0.1;
  slide.profile.angular_frequency_rad_per_s = 4.0;
  slide.profile.phase_rad = 0.3;
  model.drivers = {angle, slide};
  ASSERT_TRUE(model.Validate().ok()) << model.Validate();
  const SpatialSystem s(model);
  VectorXd q, v;
  GeneralState(s, &q, &v);
  const double t = 0.4;
  const int row = s.row_of_driver(1);
  ASSERT_EQ(row, s.num_constraints() - 1);
  VectorXd phi, phi_t, gamma, phi_plus, phi_minus;
  ASSERT_EQ(s.Constraints(t, q, &phi), 0);
  EXPECT_NEAR(phi[row], s.JointTranslation(1, q) - slide.profile.At(t).q, 1e-15);
  MatrixXd phi_q;
  ASSERT_EQ(s.ConstraintJacobian(t, q, &phi_q), 0);
  for (int k = 0; k < q.size(); ++k) {
    VectorXd plus = q, minus = q;
    plus[k] += kStep;
    minus[k] -= kStep;
    ASSERT_EQ(s.Constraints(t, plus, &phi_plus), 0);
    ASSERT_EQ(s.Constraints(t, minus, &phi_minus), 0);
    EXPECT_NEAR(phi_q(row, k), (phi_plus[row] - phi_minus[row]) / (2 * kStep), kDifferenceTolerance) << k;
  }
  ASSERT_EQ(s.ConstraintTimeDerivative(t, q, &phi_t), 0);
  ASSERT_EQ(s.Constraints(t + kStep, q, &phi_plus), 0);
  ASSERT_EQ(s.Constraints(t - kStep, q, &phi_minus), 0);
  EXPECT_NEAR(phi_t[row], (phi_plus[row] - phi_minus[row]) / (2 * kStep), kDifferenceTolerance);
  ASSERT_EQ(s.AccelerationRightSide(t, q, v, &gamma), 0);
  auto rate = [&](double h) {
    MatrixXd phi_q_h;
    VectorXd phi_t_h;
    EXPECT_EQ(s.ConstraintJacobian(t + h, q + h * v, &phi_q_h), 0);
    EXPECT_EQ(s.ConstraintTimeDerivative(t + h, q + h * v, &phi_t_h), 0);
    return VectorXd(phi_q_h * v + phi_t_h);
  };
  const VectorXd difference = (rate(kStep) - rate(-kStep)) / (2 * kStep);
  EXPECT_NEAR(difference[row], -gamma[row], kDifferenceTolerance);
  EXPECT_EQ(s.RowOwner(row), "the driver of joint 'between'");
}

// The mass matrix is the Hessian of the kinetic energy in v on |p| = 1,
// up to the term along p (which lies in the normalization row's reaction):
// v^T M v / 2 equals the kinetic energy for rates tangent to the sphere.
TEST(SpatialSystem, MassMatrixGivesTheKineticEnergy) {
  const Model model = TwoBodies(Joint::Kind::kSpherical);
  const SpatialSystem s(model);
  Model moving = model;
  moving.bodies[0].velocity_m_per_s = {0.3, -0.2, 0.5};
  moving.bodies[0].angular_velocity_rad_per_s = {1.0, -2.0, 0.5};
  moving.bodies[1].angular_velocity_rad_per_s = {-0.4, 0.3, 3.0};
  const SpatialSystem with_rates(moving);
  const VectorXd q = with_rates.InitialGuess(), v = with_rates.InitialVelocityGuess();
  MatrixXd mass;
  ASSERT_EQ(s.MassMatrix(q, &mass), 0);
  const double expected = 0.5 * 2.0 * 0.3 * 0.3 + 0.5 * 2.0 * 0.2 * 0.2 + 0.5 * 2.0 * 0.5 * 0.5;
  double rotational = 0.0;
  for (int b = 0; b < 2; ++b) {
    const Vector3d w = moving.bodies[static_cast<size_t>(b)].angular_velocity_rad_per_s;
    const Matrix3d r = moving.bodies[static_cast<size_t>(b)].orientation;
    rotational += 0.5 * w.dot(r * moving.bodies[static_cast<size_t>(b)].inertia_kg_m2 * r.transpose() * w);
  }
  EXPECT_NEAR(0.5 * v.dot(mass * v), expected + rotational, 1e-12);
  EXPECT_NEAR(s.KineticEnergy(q, v), expected + rotational, 1e-12);
  // Positive definite, as the integrator's consistent start assumes.
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<MatrixXd>(mass).eigenvalues().minCoeff(), 0.0);
}

// The world angular velocity read back from the Euler parameter rates.
TEST(SpatialSystem, AngularVelocityRoundTrips) {
  Model model = TwoBodies(Joint::Kind::kSpherical);
  model.bodies[1].angular_velocity_rad_per_s = {0.7, -1.1, 2.3};
  const SpatialSystem s(model);
  const VectorXd q = s.InitialGuess(), v = s.InitialVelocityGuess();
  EXPECT_LT((s.AngularVelocity(1, q, v) - Vector3d(0.7, -1.1, 2.3)).norm(), 1e-14);
  EXPECT_LT((s.BodyRotation(1, q) - model.bodies[1].orientation).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(SpatialAssembly, ClosesAPerturbedLoopAndCountsItsFreedom) {
  // A body on a revolute joint to ground, started 0.05 m and 0.1 rad off.
  Model model;
  model.bodies.push_back(Brick("door", {0.52, 0.03, 0.0}, AxisAngle({1, 0.5, 0}, 0.1)));
  model.joints.push_back({"hinge", Joint::Kind::kRevolute, FrameOn(kGround, {0, 0, 0}), FrameOn(0, {-0.5, 0, 0})});
  ASSERT_TRUE(model.Validate().ok());
  const SpatialSystem s(model);
  const SpatialAssembly a = AssembleSpatial(s, 0.0);
  ASSERT_TRUE(a.failure.ok()) << a.failure.reason;
  VectorXd phi;
  ASSERT_EQ(s.Constraints(0.0, a.q, &phi), 0);
  EXPECT_LT(Unscaled(s, phi).cwiseAbs().maxCoeff(), 1e-12);
  // 7 coordinates less the norm row and the hinge's 5: the rotation about the hinge.
  EXPECT_EQ(a.degrees_of_freedom, 1);
  EXPECT_EQ(a.redundant_rows, 0);
}

TEST(SpatialAssembly, NamesTheJointThatCannotClose) {
  Model model;
  model.bodies.push_back(Brick("rod", {0, 0, 0}, Matrix3d::Identity()));
  // Both ends of a 1 m rod on ground points 3 m apart.
  model.joints.push_back({"left", Joint::Kind::kSpherical, FrameOn(kGround, {-1.5, 0, 0}), FrameOn(0, {-0.5, 0, 0})});
  model.joints.push_back({"right", Joint::Kind::kSpherical, FrameOn(kGround, {1.5, 0, 0}), FrameOn(0, {0.5, 0, 0})});
  const SpatialSystem s(model);
  const SpatialAssembly a = AssembleSpatial(s, 0.0);
  ASSERT_FALSE(a.failure.ok());
  EXPECT_EQ(a.failure.kind, spec::FailureKind::kAssembly);
  EXPECT_NE(a.failure.reason.find("spherical joint '"), std::string::npos) << a.failure.reason;
}

TEST(SpatialModel, RefusesAnImpossibleInertia) {
  Model model;
  model.bodies.push_back(Brick("plate", {0, 0, 0}, Matrix3d::Identity()));
  model.bodies[0].inertia_kg_m2 = Vector3d(1.0, 1.0, 3.0).asDiagonal();
  const absl::Status status = model.Validate();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("body 'plate'"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("triangle inequality"), std::string::npos) << status.message();
}

TEST(SpatialModel, RefusesAnOrientationThatIsNotARotation) {
  Model model;
  model.bodies.push_back(Brick("mirror", {0, 0, 0}, Vector3d(1.0, 1.0, -1.0).asDiagonal()));
  const absl::Status status = model.Validate();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("body 'mirror': orientation"), std::string::npos) << status.message();
}

TEST(SpatialModel, RefusesADriverOnASphericalJoint) {
  Model model = TwoBodies(Joint::Kind::kSpherical);
  model.drivers.push_back({1, {}});
  const absl::Status status = model.Validate();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("spherical joint 'between'"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("expected a revolute or cylindrical joint"), std::string::npos);
}

TEST(SpatialModel, RefusesASlideDriverOnARevoluteJoint) {
  Model model = TwoBodies(Joint::Kind::kRevolute);
  Driver d;
  d.joint = 1;
  d.slide = true;
  model.drivers.push_back(d);
  const absl::Status status = model.Validate();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("drives the slide of revolute joint 'between', expected a prismatic or "
                                  "cylindrical joint"),
            std::string::npos)
      << status.message();
}

TEST(SpatialModel, RefusesAJointWithinOneBody) {
  Model model = TwoBodies(Joint::Kind::kRevolute);
  model.joints[1].b.body = 0;
  const absl::Status status = model.Validate();
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("revolute joint 'between': both frames are on body 'one'"), std::string::npos)
      << status.message();
}

}  // namespace
}  // namespace mbopt::spatial
