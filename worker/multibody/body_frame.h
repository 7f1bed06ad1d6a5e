// The pose and velocity of one body of a Mechanism read from the absolute
// coordinates q = (x_i, y_i, phi_i) (and v = dq/dt): shared by the residual
// (mechanism.cc) and its derivatives (mechanism_derivatives.cc).
#pragma once

#include <cmath>

#include <Eigen/Dense>

#include "worker/multibody/model.h"

namespace mbopt::multibody::frame {

inline Eigen::Matrix2d Rotation(double phi) {
  const double c = std::cos(phi), s = std::sin(phi);
  Eigen::Matrix2d a;
  a << c, -s, s, c;
  return a;
}
// dA/dphi: A rotated by a further quarter turn.
inline Eigen::Matrix2d RotationDerivative(double phi) {
  const double c = std::cos(phi), s = std::sin(phi);
  Eigen::Matrix2d b;
  b << -s, -c, c, -s;
  return b;
}

// The kinematic quantities of one body (ground: identity, at rest).
struct Frame {
  int body = kGround;
  Eigen::Vector2d r = Eigen::Vector2d::Zero(), r_dot = Eigen::Vector2d::Zero();
  double phi = 0.0, phi_dot = 0.0;
  Eigen::Matrix2d a = Eigen::Matrix2d::Identity(), b = Eigen::Matrix2d::Zero();
  int column = -1;  // first coordinate of the body, -1 for ground

  Eigen::Vector2d Position(const Eigen::Vector2d& s) const { return r + a * s; }
  Eigen::Vector2d Velocity(const Eigen::Vector2d& s) const { return r_dot + b * s * phi_dot; }
};

inline Frame FrameOf(int body, const Eigen::VectorXd& q, const Eigen::VectorXd* v) {
  Frame f;
  f.body = body;
  if (body == kGround) return f;
  f.column = 3 * body;
  f.r = q.segment<2>(f.column);
  f.phi = q[f.column + 2];
  f.a = Rotation(f.phi);
  f.b = RotationDerivative(f.phi);
  if (v != nullptr) {
    f.r_dot = v->segment<2>(f.column);
    f.phi_dot = (*v)[f.column + 2];
  }
  return f;
}

}  // namespace mbopt::multibody::frame
