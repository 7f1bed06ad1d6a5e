#include "worker/spatial/spatial_system.h"

#include <cmath>

#include "absl/strings/str_format.h"
#include "worker/spatial/euler_parameters.h"
#include "worker/spatial/pair_vectors.h"
#include "worker/spatial/spatial_force_elements.h"

namespace mbopt::spatial {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::Vector4d;
using Eigen::VectorXd;

constexpr int kBlock = SpatialSystem::kCoordinatesPerBody;
static_assert(kBlock == pair::kBlock);
constexpr double kNormRowScale = SpatialSystem::kNormRowScale;

using pair::BodyCoordinates;
using pair::CoordinatesOf;
using pair::Dot;
using pair::FixedIn;
using pair::FrameOf;
using pair::FrameVectors;
using pair::JointEquations;
using pair::Minus;
using pair::PairScalar;
using pair::PairVector;
using pair::Scatter;

bool AllFinite(const VectorXd& x) { return x.allFinite(); }

}  // namespace

SpatialSystem::SpatialSystem(const Model& model) : model_(model), spring_angles_(model.rotational_springs.size()) {
  int row = static_cast<int>(model_.bodies.size());
  for (const Joint& j : model_.joints) {
    joint_row_.push_back(row);
    row += JointEquationCount(j.kind);
  }
  for (size_t i = 0; i < model_.drivers.size(); ++i) driver_row_.push_back(row++);
  num_rows_ = row;
}

std::string SpatialSystem::RowOwner(int row) const {
  if (row < static_cast<int>(model_.bodies.size())) return "the unit norm of " + model_.BodyName(row);
  for (size_t d = 0; d < driver_row_.size(); ++d) {
    if (driver_row_[d] == row) {
      return "the driver of joint '" + model_.joints[static_cast<size_t>(model_.drivers[d].joint)].name + "'";
    }
  }
  for (size_t j = joint_row_.size(); j-- > 0;) {
    if (joint_row_[j] <= row) {
      const Joint& joint = model_.joints[j];
      return absl::StrFormat("%s joint '%s' (equation %d)", JointKindName(joint.kind), joint.name,
                             row - joint_row_[j] + 1);
    }
  }
  return absl::StrFormat("row %d", row);
}

int SpatialSystem::MassMatrix(const VectorXd& q, Eigen::MatrixXd* mass) const {
  const int n = num_coordinates();
  mass->setZero(n, n);
  for (size_t i = 0; i < model_.bodies.size(); ++i) {
    const Body& b = model_.bodies[i];
    const int at = kBlock * static_cast<int>(i);
    const Vector4d p = q.segment<4>(at + 3);
    const Eigen::Matrix<double, 3, 4> l = BodyRateMatrix(p);
    mass->block<3, 3>(at, at) = b.mass_kg * Matrix3d::Identity();
    // 4 L^T J L is singular along p; the p p^T term lies in the
    // normalization row's reaction (see the header).
    const double along_p = 4.0 * b.inertia_kg_m2.trace() / 3.0;
    mass->block<4, 4>(at + 3, at + 3) = 4.0 * l.transpose() * b.inertia_kg_m2 * l + along_p * p * p.transpose();
  }
  return mass->allFinite() ? 0 : 1;
}

int SpatialSystem::AppliedForces(double t, const VectorXd& q, const VectorXd& v, VectorXd* forces) const {
  forces->setZero(num_coordinates());
  for (size_t i = 0; i < model_.bodies.size(); ++i) {
    const Body& b = model_.bodies[i];
    const int at = kBlock * static_cast<int>(i);
    if (model_.gravity_m_per_s2) forces->segment<3>(at) += b.mass_kg * *model_.gravity_m_per_s2;
    const Vector4d p = q.segment<4>(at + 3), p_dot = v.segment<4>(at + 3);
    const Eigen::Matrix<double, 3, 4> l_dot = BodyRateMatrix(p_dot);
    forces->segment<4>(at + 3) += 8.0 * l_dot.transpose() * b.inertia_kg_m2 * l_dot * p;
  }
  VectorXd elements;
  if (ElementForces(t, q, v, &elements) != 0) return 1;
  *forces += elements;
  return AllFinite(*forces) ? 0 : 1;
}

int SpatialSystem::ElementForces(double t, const VectorXd& q, const VectorXd& v, VectorXd* forces) const {
  failure_reason_.clear();
  forces->setZero(num_coordinates());
  for (const SpringDamper& s : model_.springs) {
    const PairVector d = Minus(FixedIn(CoordinatesOf(s.b.body, q, &v), 1, s.b.position_m, true),
                               FixedIn(CoordinatesOf(s.a.body, q, &v), 0, s.a.position_m, true));
    const double length = d.x.norm();
    // The force's direction is undefined at zero length: the step is cut.
    if (!(length > 0.0)) return 1;
    const Vector3d unit = d.x / length;
    const double tension = SpringTension(s, length, unit.dot(d.x_dot), continue_past_bounds_);
    const pair::PairRow pair_row = -tension * unit.transpose() * d.jacobian;
    Eigen::MatrixXd scattered = Eigen::MatrixXd::Zero(1, num_coordinates());
    Scatter(pair_row, s.a.body, s.b.body, scattered);
    *forces += scattered.row(0).transpose();
  }
  return AddForceElementForces(model_, t, q, v, continue_past_bounds_, &spring_angles_, forces, &failure_reason_);
}

void SpatialSystem::EvaluateRows(double t, const VectorXd& q, const VectorXd* v, VectorXd* phi,
                                 Eigen::MatrixXd* phi_q, VectorXd* phi_t, VectorXd* gamma) const {
  const int n = num_coordinates(), m = num_rows_;
  if (phi != nullptr) phi->setZero(m);
  if (phi_q != nullptr) phi_q->setZero(m, n);
  if (phi_t != nullptr) phi_t->setZero(m);
  if (gamma != nullptr) gamma->setZero(m);
  auto put = [&](int row, const PairScalar& s, int body_a, int body_b) {
    if (phi != nullptr) (*phi)[row] = s.f;
    if (phi_q != nullptr) Scatter(s.jacobian, body_a, body_b, phi_q->middleRows(row, 1));
    if (gamma != nullptr) (*gamma)[row] = -s.f_ddot0;
  };
  for (int i = 0; i < static_cast<int>(model_.bodies.size()); ++i) {
    const Vector4d p = q.segment<4>(kBlock * i + 3);
    if (phi != nullptr) (*phi)[i] = kNormRowScale * (p.squaredNorm() - 1.0);
    if (phi_q != nullptr) phi_q->block<1, 4>(i, kBlock * i + 3) = kNormRowScale * 2.0 * p.transpose();
    if (gamma != nullptr) (*gamma)[i] = -kNormRowScale * 2.0 * v->segment<4>(kBlock * i + 3).squaredNorm();
  }
  for (size_t j = 0; j < model_.joints.size(); ++j) {
    const Joint& joint = model_.joints[j];
    const std::vector<PairScalar> rows = JointEquations(joint, q, v);
    for (size_t k = 0; k < rows.size(); ++k) put(joint_row_[j] + static_cast<int>(k), rows[k], joint.a.body, joint.b.body);
  }
  for (size_t d = 0; d < model_.drivers.size(); ++d) {
    if (model_.drivers[d].slide) {
      PutSlideDriverRow(t, d, q, v, phi, phi_q, phi_t, gamma);
      continue;
    }
    // sin(angle - angle(t)) = sin(angle) cos(angle(t)) - cos(angle) sin(angle(t)),
    // with sin(angle) = x_b.y_a and cos(angle) = x_b.x_a: smooth in q, and
    // zero at the prescribed angle.
    const Joint& joint = model_.joints[static_cast<size_t>(model_.drivers[d].joint)];
    const FrameVectors a = FrameOf(joint.a, 0, q, v), b = FrameOf(joint.b, 1, q, v);
    const PairScalar sine = Dot(b.x, a.y), cosine = Dot(b.x, a.x);
    const multibody::Profile::Value angle = model_.drivers[d].profile.At(t);
    const double c = std::cos(angle.q), s = std::sin(angle.q);
    const int row = driver_row_[d];
    PairScalar f;
    f.f = c * sine.f - s * cosine.f;
    f.jacobian = c * sine.jacobian - s * cosine.jacobian;
    f.f_ddot0 = c * sine.f_ddot0 - s * cosine.f_ddot0;
    put(row, f, joint.a.body, joint.b.body);
    const double along = s * sine.f + c * cosine.f;
    if (phi_t != nullptr) (*phi_t)[row] = -angle.q_dot * along;
    if (gamma != nullptr) {
      // -(Phi_q v)_q v - 2 Phi_qt v - Phi_tt.
      (*gamma)[row] = -f.f_ddot0 + 2.0 * angle.q_dot * (s * sine.f_dot + c * cosine.f_dot) +
                      angle.q_ddot * along + angle.q_dot * angle.q_dot * f.f;
    }
  }
}

void SpatialSystem::PutSlideDriverRow(double t, size_t d, const VectorXd& q, const VectorXd* v, VectorXd* phi,
                                      Eigen::MatrixXd* phi_q, VectorXd* phi_t, VectorXd* gamma) const {
  // z_a . (o_b - o_a) - s(t): the slide is linear in the prescribed value,
  // so Phi_t = -s', Phi_tt = -s'' and Phi_qt = 0.
  const Joint& joint = model_.joints[static_cast<size_t>(model_.drivers[d].joint)];
  const FrameVectors a = FrameOf(joint.a, 0, q, v), b = FrameOf(joint.b, 1, q, v);
  const PairScalar slide = Dot(a.z, Minus(b.origin, a.origin));
  const multibody::Profile::Value s = model_.drivers[d].profile.At(t);
  const int row = driver_row_[d];
  if (phi != nullptr) (*phi)[row] = slide.f - s.q;
  if (phi_q != nullptr) Scatter(slide.jacobian, joint.a.body, joint.b.body, phi_q->middleRows(row, 1));
  if (phi_t != nullptr) (*phi_t)[row] = -s.q_dot;
  if (gamma != nullptr) (*gamma)[row] = -slide.f_ddot0 + s.q_ddot;
}

int SpatialSystem::Constraints(double t, const VectorXd& q, VectorXd* phi) const {
  EvaluateRows(t, q, nullptr, phi, nullptr, nullptr, nullptr);
  return AllFinite(*phi) ? 0 : 1;
}

int SpatialSystem::ConstraintJacobian(double t, const VectorXd& q, Eigen::MatrixXd* phi_q) const {
  EvaluateRows(t, q, nullptr, nullptr, phi_q, nullptr, nullptr);
  return phi_q->allFinite() ? 0 : 1;
}

int SpatialSystem::ConstraintTimeDerivative(double t, const VectorXd& q, VectorXd* phi_t) const {
  EvaluateRows(t, q, nullptr, nullptr, nullptr, phi_t, nullptr);
  return AllFinite(*phi_t) ? 0 : 1;
}

int SpatialSystem::AccelerationRightSide(double t, const VectorXd& q, const VectorXd& v, VectorXd* gamma) const {
  EvaluateRows(t, q, &v, nullptr, nullptr, nullptr, gamma);
  return AllFinite(*gamma) ? 0 : 1;
}

VectorXd SpatialSystem::InitialGuess() const {
  VectorXd q(num_coordinates());
  for (size_t i = 0; i < model_.bodies.size(); ++i) {
    const Body& b = model_.bodies[i];
    q.segment<3>(kBlock * static_cast<int>(i)) = b.position_m;
    q.segment<4>(kBlock * static_cast<int>(i) + 3) = EulerParametersOf(b.orientation);
  }
  return q;
}

VectorXd SpatialSystem::InitialVelocityGuess() const {
  const VectorXd q = InitialGuess();
  VectorXd v(num_coordinates());
  for (size_t i = 0; i < model_.bodies.size(); ++i) {
    const Body& b = model_.bodies[i];
    const int at = kBlock * static_cast<int>(i);
    v.segment<3>(at) = b.velocity_m_per_s;
    v.segment<4>(at + 3) = EulerParameterRate(q.segment<4>(at + 3), b.angular_velocity_rad_per_s);
  }
  return v;
}

Vector3d SpatialSystem::PointPosition(const Point& p, const VectorXd& q) const {
  return FixedIn(CoordinatesOf(p.body, q, nullptr), 0, p.position_m, true).x;
}

Vector3d SpatialSystem::PointVelocity(const Point& p, const VectorXd& q, const VectorXd& v) const {
  return FixedIn(CoordinatesOf(p.body, q, &v), 0, p.position_m, true).x_dot;
}

Matrix3d SpatialSystem::BodyRotation(int body, const VectorXd& q) const {
  return RotationOf(CoordinatesOf(body, q, nullptr).p);
}

Vector3d SpatialSystem::AngularVelocity(int body, const VectorXd& q, const VectorXd& v) const {
  const BodyCoordinates c = CoordinatesOf(body, q, &v);
  return 2.0 * WorldRateMatrix(c.p) * c.p_dot;
}

Vector3d SpatialSystem::BodyAngularVelocity(int body, const VectorXd& q, const VectorXd& v) const {
  const BodyCoordinates c = CoordinatesOf(body, q, &v);
  return 2.0 * BodyRateMatrix(c.p) * c.p_dot;
}

double SpatialSystem::JointAngle(int joint, const VectorXd& q) const {
  const Joint& j = model_.joints[static_cast<size_t>(joint)];
  const FrameVectors a = FrameOf(j.a, 0, q, nullptr), b = FrameOf(j.b, 1, q, nullptr);
  return std::atan2(b.x.x.dot(a.y.x), b.x.x.dot(a.x.x));
}

double SpatialSystem::JointTranslation(int joint, const VectorXd& q) const {
  const Joint& j = model_.joints[static_cast<size_t>(joint)];
  const FrameVectors a = FrameOf(j.a, 0, q, nullptr), b = FrameOf(j.b, 1, q, nullptr);
  return a.z.x.dot(b.origin.x - a.origin.x);
}

double SpatialSystem::JointAngleRate(int joint, const VectorXd& q, const VectorXd& v) const {
  const Joint& j = model_.joints[static_cast<size_t>(joint)];
  const FrameVectors a = FrameOf(j.a, 0, q, &v), b = FrameOf(j.b, 1, q, &v);
  // d/dt atan2(s, c) = (c s' - s c') / (c^2 + s^2).
  const double sine = b.x.x.dot(a.y.x), cosine = b.x.x.dot(a.x.x);
  const double sine_dot = b.x.x_dot.dot(a.y.x) + b.x.x.dot(a.y.x_dot);
  const double cosine_dot = b.x.x_dot.dot(a.x.x) + b.x.x.dot(a.x.x_dot);
  return (cosine * sine_dot - sine * cosine_dot) / (cosine * cosine + sine * sine);
}

double SpatialSystem::JointTranslationRate(int joint, const VectorXd& q, const VectorXd& v) const {
  const Joint& j = model_.joints[static_cast<size_t>(joint)];
  const FrameVectors a = FrameOf(j.a, 0, q, &v), b = FrameOf(j.b, 1, q, &v);
  return a.z.x_dot.dot(b.origin.x - a.origin.x) + a.z.x.dot(b.origin.x_dot - a.origin.x_dot);
}

Vector3d SpatialSystem::PointAcceleration(const Point& p, const VectorXd& q, const VectorXd& v,
                                          const VectorXd& a) const {
  if (p.body == kGround) return Vector3d::Zero();
  const BodyCoordinates c = CoordinatesOf(p.body, q, &v);
  const int at = kBlock * p.body;
  // A(p) s is quadratic in p: d2(A s)/dt2 = (d(A s)/dp) p'' + 2 A(p') s.
  return a.segment<3>(at) + RotatedVectorJacobian(c.p, p.position_m) * a.segment<4>(at + 3) +
         2.0 * RotationOf(c.p_dot) * p.position_m;
}

double SpatialSystem::KineticEnergy(const VectorXd& q, const VectorXd& v) const {
  double energy = 0.0;
  for (size_t i = 0; i < model_.bodies.size(); ++i) {
    const Body& b = model_.bodies[i];
    const Vector3d w = BodyAngularVelocity(static_cast<int>(i), q, v);
    energy += 0.5 * b.mass_kg * v.segment<3>(kBlock * static_cast<int>(i)).squaredNorm() +
              0.5 * w.dot(b.inertia_kg_m2 * w);
  }
  return energy;
}

double SpatialSystem::PotentialEnergy(const VectorXd& q) const {
  double energy = 0.0;
  if (model_.gravity_m_per_s2) {
    for (size_t i = 0; i < model_.bodies.size(); ++i) {
      energy -= model_.bodies[i].mass_kg * model_.gravity_m_per_s2->dot(q.segment<3>(kBlock * static_cast<int>(i)));
    }
  }
  for (const SpringDamper& s : model_.springs) {
    energy += SpringStrainEnergy(s, (PointPosition(s.b, q) - PointPosition(s.a, q)).norm());
  }
  return energy + ForceElementPotentialEnergy(model_, q, &spring_angles_);
}

double SpatialSystem::RotationalSpringTorque(int spring, const VectorXd& q, const VectorXd& v) const {
  return spatial::RotationalSpringTorque(model_, spring, q, v, &spring_angles_);
}

// The springs' curve bounds, then the bushings'.
int SpatialSystem::num_validity_bounds() const {
  return SpringCurveBoundCount(model_) + BushingAngleBoundCount(model_);
}

void SpatialSystem::ValidityBounds(double /*t*/, const VectorXd& q, const VectorXd& v, double* g) const {
  SpringCurveBounds(model_, q, v, g);
  BushingAngleBounds(model_, q, g + SpringCurveBoundCount(model_));
}

std::string SpatialSystem::BoundReason(int bound, double t, const VectorXd& q, const VectorXd& v) const {
  const int springs = SpringCurveBoundCount(model_);
  return bound < springs ? SpringCurveBoundReason(model_, bound, t, q, v)
                         : BushingAngleBoundReason(model_, bound - springs, t, q);
}

Vector3d SpatialSystem::AngularMomentum(const VectorXd& q, const VectorXd& v) const {
  Vector3d h = Vector3d::Zero();
  for (size_t i = 0; i < model_.bodies.size(); ++i) {
    const Body& b = model_.bodies[i];
    const int body = static_cast<int>(i), at = kBlock * body;
    h += b.mass_kg * q.segment<3>(at).cross(v.segment<3>(at)) +
         BodyRotation(body, q) * (b.inertia_kg_m2 * BodyAngularVelocity(body, q, v));
  }
  return h;
}

}  // namespace mbopt::spatial
