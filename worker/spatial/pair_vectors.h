// The building blocks of SpatialSystem's joint and driver equations: a
// vector fixed in a body (a point r + A(p) s, or a direction A(p) s), the
// difference of two such, and the dot product of two, each with its value,
// rate, second time derivative at zero accelerations (for gamma) and
// Jacobian over the two bodies' coordinates, and on request its Hessian
// (the Newton matrix's curvature terms). A joint's two bodies are slot 0
// (frame a's body) and slot 1 (b's), 7 coordinates each.
//
// A(p) is quadratic in p, so for a fixed vector c the Hessian of c^T A(p) s
// in p is a constant 4 x 4 matrix (QuadraticFormHessian): the equations'
// second derivatives are exact anywhere, like their Jacobians.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Dense>

#include "worker/spatial/spatial_model.h"

namespace mbopt::spatial::pair {

inline constexpr int kBlock = 7;  // coordinates per body
inline constexpr int kPairColumns = 2 * kBlock;
using PairJacobian3 = Eigen::Matrix<double, 3, kPairColumns>;
using PairRow = Eigen::Matrix<double, 1, kPairColumns>;
using PairHessian = Eigen::Matrix<double, kPairColumns, kPairColumns>;

struct BodyCoordinates {
  Eigen::Vector3d r = Eigen::Vector3d::Zero(), r_dot = Eigen::Vector3d::Zero();
  Eigen::Vector4d p = Eigen::Vector4d(1.0, 0.0, 0.0, 0.0), p_dot = Eigen::Vector4d::Zero();
  bool ground = true;
};

// Ground (kGround) has fixed coordinates; v may be null (rates zero).
BodyCoordinates CoordinatesOf(int body, const Eigen::VectorXd& q, const Eigen::VectorXd* v);

// The part of a pair vector that is quadratic in a body's p: sign * A(p) s.
struct QuadraticTerm {
  int slot = 0;
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  double sign = 1.0;
};

struct PairVector {
  Eigen::Vector3d x = Eigen::Vector3d::Zero(), x_dot = Eigen::Vector3d::Zero(), x_ddot0 = Eigen::Vector3d::Zero();
  PairJacobian3 jacobian = PairJacobian3::Zero();
  std::array<QuadraticTerm, 2> terms{};
  int num_terms = 0;
  bool with_hessian = false;  // the scalars built from it fill their Hessians
};

struct PairScalar {
  double f = 0.0, f_dot = 0.0, f_ddot0 = 0.0;
  PairRow jacobian = PairRow::Zero();
  PairHessian hessian = PairHessian::Zero();  // only when asked for
};

// The Hessian in p of c^T A(p) s (4 x 4, constant).
Eigen::Matrix4d QuadraticFormHessian(const Eigen::Vector3d& c, const Eigen::Vector3d& s);

// r + A(p) s for a point (with_origin), A(p) s for a direction.
PairVector FixedIn(const BodyCoordinates& c, int slot, const Eigen::Vector3d& s, bool with_origin,
                   bool with_hessian = false);
PairVector Minus(const PairVector& a, const PairVector& b);
PairScalar Dot(const PairVector& a, const PairVector& b);
PairScalar Component(const PairVector& a, int k);

// A frame's origin and axes in world axes.
struct FrameVectors {
  PairVector origin, x, y, z;
};
FrameVectors FrameOf(const Frame& f, int slot, const Eigen::VectorXd& q, const Eigen::VectorXd* v,
                     bool with_hessian = false);

// The scalar equations of a joint, in the order docs/physics.md lists them.
std::vector<PairScalar> JointEquations(const Joint& joint, const Eigen::VectorXd& q, const Eigen::VectorXd* v,
                                       bool with_hessian = false);

// Adds a pair's row (or rows) into a matrix over all coordinates.
template <class PairMatrix>
void Scatter(const PairMatrix& pair, int body_a, int body_b, Eigen::Ref<Eigen::MatrixXd> out) {
  if (body_a != kGround) out.middleCols(kBlock * body_a, kBlock) += pair.leftCols(kBlock);
  if (body_b != kGround) out.middleCols(kBlock * body_b, kBlock) += pair.rightCols(kBlock);
}

// Adds weight times a pair's Hessian into an n x n matrix.
void ScatterHessian(const PairHessian& h, double weight, int body_a, int body_b, Eigen::MatrixXd* out);

// The pair's coordinates' rates (zero for ground).
Eigen::Matrix<double, kPairColumns, 1> PairRates(int body_a, int body_b, const Eigen::VectorXd& v);

}  // namespace mbopt::spatial::pair
