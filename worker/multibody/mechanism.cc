#include "worker/multibody/mechanism.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "absl/strings/str_format.h"
#include "worker/multibody/body_frame.h"

namespace mbopt::multibody {
namespace {

using Eigen::Matrix2d;
using Eigen::Vector2d;
using Eigen::VectorXd;

using frame::Frame;
using frame::FrameOf;

// Adds `weight` * d(point)/d(q_body) as the 2-row block of `rows` starting at
// `row` (a revolute-type pair of rows).
void AddPointJacobian(const Frame& f, const Vector2d& s, double weight, int row, Eigen::MatrixXd* rows) {
  if (f.column < 0) return;
  rows->block<2, 2>(row, f.column) += weight * Matrix2d::Identity();
  rows->block<2, 1>(row, f.column + 2) += weight * f.b * s;
}

}  // namespace

Mechanism::Mechanism(const Model& model) : model_(model) {
  int row = 0;
  for (size_t j = 0; j < model_.joints.size(); ++j) {
    const Joint& joint = model_.joints[j];
    joint_row_.push_back(row);
    const int rows = joint.kind == JointKind::kFixed ? 3 : joint.kind == JointKind::kPointOnLine ? 1 : 2;
    for (int k = 0; k < rows; ++k) row_joint_.push_back(static_cast<int>(j));
    row += rows;
    const double phi_a = joint.a.body == kGround ? 0.0 : model_.bodies[static_cast<size_t>(joint.a.body)].angle_rad;
    const double phi_b = joint.b.body == kGround ? 0.0 : model_.bodies[static_cast<size_t>(joint.b.body)].angle_rad;
    reference_angle_.push_back(phi_b - phi_a);
  }
  joint_rows_ = row;
  for (const Driver& d : model_.drivers) {
    driver_row_.push_back(row++);
    row_joint_.push_back(d.joint);
  }
  num_rows_ = row;
  for (size_t k = 0; k < model_.springs.size(); ++k) {
    const SpringDamper& s = model_.springs[k];
    for (const bool velocity : {false, true}) {
      if ((velocity ? s.velocity_curve : s.deflection_curve).empty()) continue;
      bounds_.push_back(Bound{static_cast<int>(k), velocity, false});
      bounds_.push_back(Bound{static_cast<int>(k), velocity, true});
    }
  }
}

void Mechanism::ValidityBounds(double t, const VectorXd& q, const VectorXd& v, double* g) const {
  for (size_t k = 0; k < bounds_.size(); ++k) {
    const Bound& b = bounds_[k];
    const SpringDamper& s = model_.springs[static_cast<size_t>(b.spring)];
    double length = 0.0, rate = 0.0;
    SpringLengthAndRate(s, q, &v, t, &length, &rate);
    const LinearTable& table = b.velocity_curve ? s.velocity_curve : s.deflection_curve;
    const double at = b.velocity_curve ? rate : length - s.free_length_m;
    g[k] = b.upper ? table.x.back() - at : at - table.x.front();
  }
}

std::string Mechanism::BoundReason(int bound, double t, const VectorXd& q, const VectorXd& v) const {
  const Bound& b = bounds_[static_cast<size_t>(bound)];
  const SpringDamper& s = model_.springs[static_cast<size_t>(b.spring)];
  double length = 0.0, rate = 0.0;
  SpringLengthAndRate(s, q, &v, t, &length, &rate);
  const LinearTable& table = b.velocity_curve ? s.velocity_curve : s.deflection_curve;
  return absl::StrFormat(
      "spring '%s' left the range of its force table at t = %.6g s: its %s reached %.6g %s, the %s end of the "
      "table (%.6g..%.6g %s)",
      s.name, t, b.velocity_curve ? "rate of length change" : "deflection",
      b.velocity_curve ? rate : length - s.free_length_m, b.velocity_curve ? "m/s" : "m",
      b.upper ? "upper" : "lower", table.x.front(), table.x.back(), b.velocity_curve ? "m/s" : "m");
}

double Mechanism::DefinedUntil_s() const {
  double until = std::numeric_limits<double>::infinity();
  auto limit = [&](const Profile& p) {
    if (p.kind == Profile::Kind::kTabulated && !p.table.empty()) until = std::min(until, p.table.back());
  };
  for (const Driver& d : model_.drivers) limit(d.profile);
  for (const InputPoint& in : model_.inputs) limit(in.displacement);
  for (const PointForce& f : model_.point_forces) {
    if (f.factor) limit(*f.factor);
  }
  for (const BodyTorque& torque : model_.torques) {
    if (torque.factor) limit(*torque.factor);
  }
  return until;
}

VectorXd Mechanism::InitialGuess() const {
  VectorXd q(num_coordinates());
  for (size_t i = 0; i < model_.bodies.size(); ++i) {
    q.segment<2>(3 * static_cast<Eigen::Index>(i)) = model_.bodies[i].position_m;
    q[3 * static_cast<Eigen::Index>(i) + 2] = model_.bodies[i].angle_rad;
  }
  return q;
}

int Mechanism::MassMatrix(const VectorXd&, Eigen::MatrixXd* mass) const {
  ++counters_.mass_matrix_evaluations;
  mass->setZero(num_coordinates(), num_coordinates());
  for (size_t i = 0; i < model_.bodies.size(); ++i) {
    const Eigen::Index c = 3 * static_cast<Eigen::Index>(i);
    (*mass)(c, c) = (*mass)(c + 1, c + 1) = model_.bodies[i].mass_kg;
    (*mass)(c + 2, c + 2) = model_.bodies[i].inertia_kg_m2;
  }
  return 0;
}

void Mechanism::EvaluateRows(double t, const VectorXd& q, const VectorXd* v, VectorXd* phi, Eigen::MatrixXd* phi_q,
                             VectorXd* phi_t, VectorXd* gamma) const {
  const int n = num_coordinates();
  if (phi != nullptr) phi->setZero(num_rows_);
  if (phi_q != nullptr) phi_q->setZero(num_rows_, n);
  if (phi_t != nullptr) phi_t->setZero(num_rows_);
  if (gamma != nullptr) gamma->setZero(num_rows_);

  // The rows of "an axis fixed in body a, dotted with d = P_b - P_a": the
  // prismatic joint's normal offset (axis rotated by a quarter turn) and a
  // prismatic driver (the axis itself). Returns the value.
  auto axis_row = [&](const Joint& joint, const Vector2d& local_axis, int row) {
    const Frame fa = FrameOf(joint.a.body, q, v), fb = FrameOf(joint.b.body, q, v);
    const Vector2d& sa = joint.a.local_m;
    const Vector2d& sb = joint.b.local_m;
    const Vector2d d = fb.Position(sb) - fa.Position(sa);
    const Vector2d axis = fa.a * local_axis;
    if (phi_q != nullptr) {
      if (fa.column >= 0) {
        phi_q->block<1, 2>(row, fa.column) -= axis.transpose();
        (*phi_q)(row, fa.column + 2) += (fa.b * local_axis).dot(d) - axis.dot(fa.b * sa);
      }
      if (fb.column >= 0) {
        phi_q->block<1, 2>(row, fb.column) += axis.transpose();
        (*phi_q)(row, fb.column + 2) += axis.dot(fb.b * sb);
      }
    }
    if (gamma != nullptr && v != nullptr) {
      const Vector2d d_dot = fb.Velocity(sb) - fa.Velocity(sa);
      const Vector2d axis_dot = fa.b * local_axis * fa.phi_dot;
      const double rest = (-fa.a * local_axis * fa.phi_dot * fa.phi_dot).dot(d) + 2.0 * axis_dot.dot(d_dot) +
                          axis.dot(-fb.a * sb * fb.phi_dot * fb.phi_dot + fa.a * sa * fa.phi_dot * fa.phi_dot);
      (*gamma)[row] -= rest;
    }
    return axis.dot(d);
  };
  // phi_b - phi_a.
  auto angle_row = [&](const Joint& joint, int row) {
    const Frame fa = FrameOf(joint.a.body, q, v), fb = FrameOf(joint.b.body, q, v);
    if (phi_q != nullptr) {
      if (fa.column >= 0) (*phi_q)(row, fa.column + 2) -= 1.0;
      if (fb.column >= 0) (*phi_q)(row, fb.column + 2) += 1.0;
    }
    return fb.phi - fa.phi;
  };

  for (size_t j = 0; j < model_.joints.size(); ++j) {
    const Joint& joint = model_.joints[j];
    const int row = joint_row_[j];
    if (joint.kind == JointKind::kPointOnLine) {
      const Vector2d normal(-std::sin(joint.axis_angle_rad), std::cos(joint.axis_angle_rad));
      const double offset = axis_row(joint, normal, row);
      if (phi != nullptr) (*phi)[row] = offset;
      continue;
    }
    if (joint.kind == JointKind::kPrismatic) {
      const Vector2d normal(-std::sin(joint.axis_angle_rad), std::cos(joint.axis_angle_rad));
      const double offset = axis_row(joint, normal, row);
      const double angle = angle_row(joint, row + 1) - ReferenceAngle(static_cast<int>(j));
      if (phi != nullptr) {
        (*phi)[row] = offset;
        (*phi)[row + 1] = angle;
      }
      continue;
    }
    // Revolute and fixed: the markers coincide.
    const Frame fa = FrameOf(joint.a.body, q, v), fb = FrameOf(joint.b.body, q, v);
    if (phi != nullptr) phi->segment<2>(row) = fa.Position(joint.a.local_m) - fb.Position(joint.b.local_m);
    if (phi_q != nullptr) {
      AddPointJacobian(fa, joint.a.local_m, 1.0, row, phi_q);
      AddPointJacobian(fb, joint.b.local_m, -1.0, row, phi_q);
    }
    if (gamma != nullptr && v != nullptr) {
      gamma->segment<2>(row) += fa.a * joint.a.local_m * fa.phi_dot * fa.phi_dot -
                                fb.a * joint.b.local_m * fb.phi_dot * fb.phi_dot;
    }
    if (joint.kind == JointKind::kFixed) {
      const double angle = angle_row(joint, row + 2) - ReferenceAngle(static_cast<int>(j));
      if (phi != nullptr) (*phi)[row + 2] = angle;
    }
  }
  for (size_t k = 0; k < model_.drivers.size(); ++k) {
    const Driver& driver = model_.drivers[k];
    const Joint& joint = model_.joints[static_cast<size_t>(driver.joint)];
    const int row = driver_row_[k];
    const Profile::Value prescribed = driver.profile.At(t);
    const bool along_axis = joint.kind == JointKind::kPrismatic || joint.kind == JointKind::kPointOnLine;
    const double coordinate = along_axis
                                  ? axis_row(joint, Vector2d(std::cos(joint.axis_angle_rad), std::sin(joint.axis_angle_rad)), row)
                                  : angle_row(joint, row);
    if (phi != nullptr) (*phi)[row] = coordinate - prescribed.q;
    if (phi_t != nullptr) (*phi_t)[row] = -prescribed.q_dot;
    if (gamma != nullptr) (*gamma)[row] += prescribed.q_ddot;
  }
}

int Mechanism::Constraints(double t, const VectorXd& q, VectorXd* phi) const {
  ++counters_.constraint_evaluations;
  EvaluateRows(t, q, nullptr, phi, nullptr, nullptr, nullptr);
  return phi->allFinite() ? 0 : 1;
}

int Mechanism::ConstraintJacobian(double t, const VectorXd& q, Eigen::MatrixXd* phi_q) const {
  ++counters_.jacobian_evaluations;
  EvaluateRows(t, q, nullptr, nullptr, phi_q, nullptr, nullptr);
  return phi_q->allFinite() ? 0 : 1;
}

int Mechanism::ConstraintTimeDerivative(double t, const VectorXd& q, VectorXd* phi_t) const {
  ++counters_.constraint_evaluations;
  EvaluateRows(t, q, nullptr, nullptr, nullptr, phi_t, nullptr);
  return phi_t->allFinite() ? 0 : 1;
}

int Mechanism::AccelerationRightSide(double t, const VectorXd& q, const VectorXd& v, VectorXd* gamma) const {
  ++counters_.constraint_evaluations;
  EvaluateRows(t, q, &v, nullptr, nullptr, nullptr, gamma);
  return gamma->allFinite() ? 0 : 1;
}

int Mechanism::AppliedForces(double t, const VectorXd& q, const VectorXd& v, VectorXd* forces) const {
  ++counters_.force_evaluations;
  forces->setZero(num_coordinates());
  // A force f (world axes) at point s of a body: f on (x, y), (B s) . f on phi.
  auto apply = [&](const Point& p, const Vector2d& f) {
    if (p.body == kGround) return;
    const Frame frame = FrameOf(p.body, q, nullptr);
    forces->segment<2>(frame.column) += f;
    (*forces)[frame.column + 2] += (frame.b * p.local_m).dot(f);
  };
  if (model_.gravity_m_per_s2.has_value()) {
    ++counters_.gravity_evaluations;
    for (size_t i = 0; i < model_.bodies.size(); ++i) {
      forces->segment<2>(3 * static_cast<Eigen::Index>(i)) += model_.bodies[i].mass_kg * *model_.gravity_m_per_s2;
    }
  }
  for (size_t k = 0; k < model_.springs.size(); ++k) {
    const SpringDamper& s = model_.springs[k];
    const Vector2d d = PointPosition(s.b, q, t) - PointPosition(s.a, q, t);
    const double length = d.norm();
    if (!(length > 0.0)) return 1;  // coincident ends: no direction (the step is retried)
    const Vector2d u = d / length;
    const double tension = SpringTension(static_cast<int>(k), q, v, t);
    if (!std::isfinite(tension)) {
      // Recoverable: a trial step may overshoot the table where the motion
      // itself stays inside; if the motion leaves it, the reason stays.
      failure_ = absl::StrFormat(
          "spring '%s' left the range of its force table at t = %.6g s (length %.6g m, free length %.6g m)", s.name,
          t, length, s.free_length_m);
      return 1;
    }
    apply(s.a, tension * u);
    apply(s.b, -tension * u);
  }
  for (const RotationalSpringDamper& r : model_.rotational_springs) {
    const Joint& joint = model_.joints[static_cast<size_t>(r.joint)];
    const double torque = -r.stiffness_n_m_per_rad * (JointCoordinate(r.joint, q) - r.free_angle_rad) -
                          r.damping_n_m_s_per_rad * JointRate(r.joint, q, v);
    if (joint.b.body != kGround) (*forces)[3 * joint.b.body + 2] += torque;
    if (joint.a.body != kGround) (*forces)[3 * joint.a.body + 2] -= torque;
  }
  for (const PointForce& f : model_.point_forces) apply(f.at, f.factor ? f.force_n * f.factor->At(t).q : f.force_n);
  for (const BodyTorque& torque : model_.torques) {
    (*forces)[3 * torque.body + 2] += torque.factor ? torque.torque_n_m * torque.factor->At(t).q : torque.torque_n_m;
  }
  for (const BeamElement& e : model_.beams) {
    const BeamNodes x = BeamCoordinates(e, q), x_dot = BeamCoordinates(e, v);
    BeamLoads loads;
    if (!EvaluateBeam(e, x, &x_dot, &loads)) return 1;  // coincident nodes: the step is retried
    const BeamNodes f = BeamInternalForces(loads);
    forces->segment<3>(3 * e.a) -= f.head<3>();
    forces->segment<3>(3 * e.b) -= f.tail<3>();
  }
  return forces->allFinite() ? 0 : 1;
}

Vector2d Mechanism::PointPosition(const Point& p, const VectorXd& q, double t) const {
  if (p.input >= 0) {
    const InputPoint& in = model_.inputs[static_cast<size_t>(p.input)];
    return in.position_m + in.direction * in.displacement.At(t).q;
  }
  return FrameOf(p.body, q, nullptr).Position(p.local_m);
}

Vector2d Mechanism::PointVelocity(const Point& p, const VectorXd& q, const VectorXd& v, double t) const {
  if (p.input >= 0) {
    const InputPoint& in = model_.inputs[static_cast<size_t>(p.input)];
    return in.direction * in.displacement.At(t).q_dot;
  }
  return FrameOf(p.body, q, &v).Velocity(p.local_m);
}

Vector2d Mechanism::PointAcceleration(const Point& p, const VectorXd& q, const VectorXd& v, const VectorXd& a,
                                      double t) const {
  if (p.input >= 0) {
    const InputPoint& in = model_.inputs[static_cast<size_t>(p.input)];
    return in.direction * in.displacement.At(t).q_ddot;
  }
  if (p.body == kGround) return Vector2d::Zero();
  const Frame f = FrameOf(p.body, q, &v);
  const double phi_ddot = a[f.column + 2];
  return a.segment<2>(f.column) + f.b * p.local_m * phi_ddot - f.a * p.local_m * f.phi_dot * f.phi_dot;
}

double Mechanism::JointCoordinate(int joint, const VectorXd& q) const {
  const Joint& j = model_.joints[static_cast<size_t>(joint)];
  const Frame fa = FrameOf(j.a.body, q, nullptr), fb = FrameOf(j.b.body, q, nullptr);
  if (j.kind != JointKind::kPrismatic && j.kind != JointKind::kPointOnLine) return fb.phi - fa.phi;
  const Vector2d axis = fa.a * Vector2d(std::cos(j.axis_angle_rad), std::sin(j.axis_angle_rad));
  return axis.dot(fb.Position(j.b.local_m) - fa.Position(j.a.local_m));
}

double Mechanism::JointRate(int joint, const VectorXd& q, const VectorXd& v) const {
  const Joint& j = model_.joints[static_cast<size_t>(joint)];
  const Frame fa = FrameOf(j.a.body, q, &v), fb = FrameOf(j.b.body, q, &v);
  if (j.kind != JointKind::kPrismatic && j.kind != JointKind::kPointOnLine) return fb.phi_dot - fa.phi_dot;
  const Vector2d local_axis(std::cos(j.axis_angle_rad), std::sin(j.axis_angle_rad));
  const Vector2d d = fb.Position(j.b.local_m) - fa.Position(j.a.local_m);
  const Vector2d d_dot = fb.Velocity(j.b.local_m) - fa.Velocity(j.a.local_m);
  return (fa.b * local_axis * fa.phi_dot).dot(d) + (fa.a * local_axis).dot(d_dot);
}

double Mechanism::SpringLength(int spring, const VectorXd& q, double t) const {
  const SpringDamper& s = model_.springs[static_cast<size_t>(spring)];
  return (PointPosition(s.b, q, t) - PointPosition(s.a, q, t)).norm();
}

void Mechanism::SpringLengthAndRate(const SpringDamper& s, const VectorXd& q, const VectorXd* v, double t,
                                    double* length, double* rate) const {
  const Vector2d d = PointPosition(s.b, q, t) - PointPosition(s.a, q, t);
  *length = d.norm();
  *rate = v != nullptr && v->size() == q.size() && *length > 0.0
              ? d.dot(PointVelocity(s.b, q, *v, t) - PointVelocity(s.a, q, *v, t)) / *length
              : 0.0;
}

double Mechanism::SpringTension(int spring, const VectorXd& q, const VectorXd& v, double t) const {
  const SpringDamper& s = model_.springs[static_cast<size_t>(spring)];
  double length = 0.0, length_rate = 0.0;
  SpringLengthAndRate(s, q, &v, t, &length, &length_rate);
  const double deflection = length - s.free_length_m;
  double elastic = s.stiffness_n_per_m * deflection, viscous = s.damping_n_s_per_m * length_rate;
  if (continue_tables_) {
    // An integrator's trial step across a table's end; the integrator stops
    // where the motion itself crosses it (ValidityBounds).
    if (!s.deflection_curve.empty()) elastic = s.deflection_curve.Continued(deflection);
    if (!s.velocity_curve.empty()) viscous = s.velocity_curve.Continued(length_rate);
    return elastic + viscous + s.actuator_force_n;
  }
  // A curve evaluated outside its table: NaN, so that the analysis fails
  // naming the spring (scene_analysis.cc) instead of extrapolating.
  if (!s.deflection_curve.empty() && !s.deflection_curve.Evaluate(deflection, &elastic)) return NAN;
  if (!s.velocity_curve.empty() && !s.velocity_curve.Evaluate(length_rate, &viscous)) return NAN;
  return elastic + viscous + s.actuator_force_n;
}

double Mechanism::KineticEnergy(const VectorXd& v) const {
  double energy = 0.0;
  for (size_t i = 0; i < model_.bodies.size(); ++i) {
    const Eigen::Index c = 3 * static_cast<Eigen::Index>(i);
    energy += 0.5 * model_.bodies[i].mass_kg * v.segment<2>(c).squaredNorm() +
              0.5 * model_.bodies[i].inertia_kg_m2 * v[c + 2] * v[c + 2];
  }
  return energy;
}

BeamNodes Mechanism::BeamCoordinates(const BeamElement& e, const VectorXd& q) const {
  BeamNodes x;
  x << q.segment<3>(3 * e.a), q.segment<3>(3 * e.b);
  return x;
}

bool Mechanism::BeamEndLoads(int element, const VectorXd& q, const VectorXd& v, BeamLoads* loads) const {
  const BeamElement& e = model_.beams[static_cast<size_t>(element)];
  if (v.size() != q.size()) return EvaluateBeam(e, BeamCoordinates(e, q), nullptr, loads);
  const BeamNodes x_dot = BeamCoordinates(e, v);
  return EvaluateBeam(e, BeamCoordinates(e, q), &x_dot, loads);
}

double Mechanism::PotentialEnergy(const VectorXd& q, double t) const {
  double energy = 0.0;
  if (model_.gravity_m_per_s2.has_value()) {
    for (size_t i = 0; i < model_.bodies.size(); ++i) {
      energy -= model_.bodies[i].mass_kg * model_.gravity_m_per_s2->dot(q.segment<2>(3 * static_cast<Eigen::Index>(i)));
    }
  }
  for (size_t k = 0; k < model_.springs.size(); ++k) {
    const SpringDamper& s = model_.springs[k];
    const double length = SpringLength(static_cast<int>(k), q, t);
    const double stretch = length - s.free_length_m;
    energy += 0.5 * s.stiffness_n_per_m * stretch * stretch + s.actuator_force_n * length;
  }
  for (const RotationalSpringDamper& r : model_.rotational_springs) {
    const double twist = JointCoordinate(r.joint, q) - r.free_angle_rad;
    energy += 0.5 * r.stiffness_n_m_per_rad * twist * twist;
  }
  for (const BeamElement& e : model_.beams) {
    BeamLoads loads;
    if (EvaluateBeam(e, BeamCoordinates(e, q), nullptr, &loads)) energy += BeamStrainEnergy(e, loads);
  }
  return energy;
}

}  // namespace mbopt::multibody
