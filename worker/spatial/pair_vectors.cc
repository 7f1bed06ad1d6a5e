#include "worker/spatial/pair_vectors.h"

#include "worker/spatial/euler_parameters.h"

namespace mbopt::spatial::pair {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using Eigen::VectorXd;

BodyCoordinates CoordinatesOf(int body, const VectorXd& q, const VectorXd* v) {
  BodyCoordinates c;
  if (body == kGround) return c;
  c.ground = false;
  const int at = kBlock * body;
  c.r = q.segment<3>(at);
  c.p = q.segment<4>(at + 3);
  if (v != nullptr) {
    c.r_dot = v->segment<3>(at);
    c.p_dot = v->segment<4>(at + 3);
  }
  return c;
}

// c^T A(p) s = (e0^2 - e.e) c.s + 2 (c.e)(e.s) + 2 e0 e.(s x c).
Eigen::Matrix4d QuadraticFormHessian(const Vector3d& c, const Vector3d& s) {
  Eigen::Matrix4d h;
  const double cs = c.dot(s);
  h(0, 0) = 2.0 * cs;
  const Vector3d cross = 2.0 * s.cross(c);
  h.block<3, 1>(1, 0) = cross;
  h.block<1, 3>(0, 1) = cross.transpose();
  h.block<3, 3>(1, 1) = -2.0 * cs * Matrix3d::Identity() + 2.0 * (c * s.transpose() + s * c.transpose());
  return h;
}

PairVector FixedIn(const BodyCoordinates& c, int slot, const Vector3d& s, bool with_origin, bool with_hessian) {
  PairVector out;
  out.with_hessian = with_hessian;
  out.x = RotationOf(c.p) * s + (with_origin ? c.r : Vector3d::Zero());
  if (c.ground) return out;
  const Matrix34d d = RotatedVectorJacobian(c.p, s);
  out.x_dot = d * c.p_dot + (with_origin ? c.r_dot : Vector3d::Zero());
  out.x_ddot0 = 2.0 * RotationOf(c.p_dot) * s;
  out.jacobian.block<3, 4>(0, kBlock * slot + 3) = d;
  if (with_origin) out.jacobian.block<3, 3>(0, kBlock * slot).setIdentity();
  out.terms[0] = {slot, s, 1.0};
  out.num_terms = 1;
  return out;
}

PairVector Minus(const PairVector& a, const PairVector& b) {
  PairVector out;
  out.x = a.x - b.x;
  out.x_dot = a.x_dot - b.x_dot;
  out.x_ddot0 = a.x_ddot0 - b.x_ddot0;
  out.jacobian = a.jacobian - b.jacobian;
  out.with_hessian = a.with_hessian || b.with_hessian;
  for (int k = 0; k < a.num_terms; ++k) out.terms[static_cast<size_t>(out.num_terms++)] = a.terms[static_cast<size_t>(k)];
  for (int k = 0; k < b.num_terms; ++k) {
    QuadraticTerm t = b.terms[static_cast<size_t>(k)];
    t.sign = -t.sign;
    out.terms[static_cast<size_t>(out.num_terms++)] = t;
  }
  return out;
}

namespace {

// Adds the Hessian of c^T a (c held fixed) to h.
void AddCurvature(const PairVector& a, const Vector3d& c, PairHessian* h) {
  for (int k = 0; k < a.num_terms; ++k) {
    const QuadraticTerm& t = a.terms[static_cast<size_t>(k)];
    const int at = kBlock * t.slot + 3;
    h->block<4, 4>(at, at) += t.sign * QuadraticFormHessian(c, t.s);
  }
}

}  // namespace

PairScalar Dot(const PairVector& a, const PairVector& b) {
  PairScalar out;
  out.f = a.x.dot(b.x);
  out.f_dot = a.x_dot.dot(b.x) + a.x.dot(b.x_dot);
  out.f_ddot0 = a.x_ddot0.dot(b.x) + 2.0 * a.x_dot.dot(b.x_dot) + a.x.dot(b.x_ddot0);
  out.jacobian = b.x.transpose() * a.jacobian + a.x.transpose() * b.jacobian;
  if (a.with_hessian || b.with_hessian) {
    out.hessian = a.jacobian.transpose() * b.jacobian + b.jacobian.transpose() * a.jacobian;
    AddCurvature(a, b.x, &out.hessian);
    AddCurvature(b, a.x, &out.hessian);
  }
  return out;
}

PairScalar Component(const PairVector& a, int k) {
  PairScalar out;
  out.f = a.x[k];
  out.f_dot = a.x_dot[k];
  out.f_ddot0 = a.x_ddot0[k];
  out.jacobian = a.jacobian.row(k);
  if (a.with_hessian) AddCurvature(a, Vector3d::Unit(k), &out.hessian);
  return out;
}

FrameVectors FrameOf(const Frame& f, int slot, const VectorXd& q, const VectorXd* v, bool with_hessian) {
  const BodyCoordinates c = CoordinatesOf(f.body, q, v);
  return {FixedIn(c, slot, f.position_m, true, with_hessian), FixedIn(c, slot, f.axes.col(0), false, with_hessian),
          FixedIn(c, slot, f.axes.col(1), false, with_hessian), FixedIn(c, slot, f.axes.col(2), false, with_hessian)};
}

std::vector<PairScalar> JointEquations(const Joint& joint, const VectorXd& q, const VectorXd* v, bool with_hessian) {
  const FrameVectors a = FrameOf(joint.a, 0, q, v, with_hessian), b = FrameOf(joint.b, 1, q, v, with_hessian);
  const PairVector d = Minus(b.origin, a.origin);
  std::vector<PairScalar> rows;
  auto coincide = [&] {
    for (int k = 0; k < 3; ++k) rows.push_back(Component(d, k));
  };
  auto on_axis = [&] {
    rows.push_back(Dot(a.x, d));
    rows.push_back(Dot(a.y, d));
  };
  auto axes_aligned = [&] {
    rows.push_back(Dot(a.z, b.x));
    rows.push_back(Dot(a.z, b.y));
  };
  switch (joint.kind) {
    case Joint::Kind::kSpherical:
      coincide();
      break;
    case Joint::Kind::kRevolute:
      coincide();
      axes_aligned();
      break;
    case Joint::Kind::kUniversal:
      coincide();
      rows.push_back(Dot(a.x, b.y));
      break;
    case Joint::Kind::kFixed:
      coincide();
      axes_aligned();
      rows.push_back(Dot(a.x, b.y));
      break;
    case Joint::Kind::kPrismatic:
      on_axis();
      axes_aligned();
      rows.push_back(Dot(a.x, b.y));
      break;
    case Joint::Kind::kCylindrical:
      on_axis();
      axes_aligned();
      break;
    case Joint::Kind::kPlanar:
      rows.push_back(Dot(a.z, d));
      axes_aligned();
      break;
    case Joint::Kind::kPointOnLine:
      on_axis();
      break;
    case Joint::Kind::kPointOnPlane:
      rows.push_back(Dot(a.z, d));
      break;
  }
  return rows;
}

void ScatterHessian(const PairHessian& h, double weight, int body_a, int body_b, Eigen::MatrixXd* out) {
  const int bodies[2] = {body_a, body_b};
  for (int i = 0; i < 2; ++i) {
    if (bodies[i] == kGround) continue;
    for (int k = 0; k < 2; ++k) {
      if (bodies[k] == kGround) continue;
      out->block<kBlock, kBlock>(kBlock * bodies[i], kBlock * bodies[k]) +=
          weight * h.block<kBlock, kBlock>(kBlock * i, kBlock * k);
    }
  }
}

Eigen::Matrix<double, kPairColumns, 1> PairRates(int body_a, int body_b, const VectorXd& v) {
  Eigen::Matrix<double, kPairColumns, 1> rates = Eigen::Matrix<double, kPairColumns, 1>::Zero();
  if (body_a != kGround) rates.head<kBlock>() = v.segment<kBlock>(kBlock * body_a);
  if (body_b != kGround) rates.tail<kBlock>() = v.segment<kBlock>(kBlock * body_b);
  return rates;
}

}  // namespace mbopt::spatial::pair
