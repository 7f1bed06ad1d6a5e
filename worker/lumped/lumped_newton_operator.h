// The Newton systems of a linear second-order model M q'' + C q' + K q = f
// in first-order form y = (q, v), solved through the second-order
// structure: (I - gamma J) x = b gives
//   x_v = (M + gamma C + gamma^2 K)^-1 (M b_v - gamma K b_u),
//   x_u = b_u + gamma x_v.
// M is diagonal (lumped masses). The n x n matrix is exact for the constant
// J and changes only with gamma; it is small, so its action on (b_u, b_v) is
// kept as one n x 2n matrix and each solve is one product. Shared by the
// plain integration and the one that carries sensitivities. Pure numerics.
#pragma once

#include <Eigen/Dense>

#include "worker/lumped/lumped_model.h"

namespace mbopt::lumped {

class LumpedNewtonOperator {
 public:
  explicit LumpedNewtonOperator(const LumpedModel& m)
      : m_(m), matrix_(m.num_coordinates(), m.num_coordinates()), rhs_map_(m.num_coordinates(), 2 * m.num_coordinates()),
        operator_(m.num_coordinates(), 2 * m.num_coordinates()), lu_(m.num_coordinates()), x_v_(m.num_coordinates()) {}

  // Forms the operator for `gamma` unless it is already formed for it; true
  // if it was formed now.
  bool Prepare(double gamma) {
    if (formed_ && gamma == gamma_) return false;
    const Eigen::Index n = m_.num_coordinates();
    matrix_ = m_.damping();
    matrix_ *= gamma;
    matrix_.noalias() += (gamma * gamma) * m_.stiffness();
    matrix_.diagonal() += m_.mass_diagonal();
    lu_.compute(matrix_);
    rhs_map_.leftCols(n) = -gamma * m_.stiffness();
    rhs_map_.rightCols(n).setZero();
    rhs_map_.rightCols(n).diagonal() = m_.mass_diagonal();
    operator_ = lu_.solve(rhs_map_);
    formed_ = true;
    gamma_ = gamma;
    return true;
  }

  // Solves in place for b = (b_u, b_v) of length 2n at the prepared gamma;
  // false if the result is not finite.
  bool Solve(double* b) {
    const Eigen::Index n = m_.num_coordinates();
    Eigen::Map<Eigen::VectorXd> all(b, 2 * n), bu(b, n), bv(b + n, n);
    x_v_.noalias() = operator_ * all;
    bv = x_v_;
    bu += gamma_ * x_v_;
    return x_v_.allFinite();
  }

 private:
  const LumpedModel& m_;
  Eigen::MatrixXd matrix_, rhs_map_, operator_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  Eigen::VectorXd x_v_;
  double gamma_ = 0.0;
  bool formed_ = false;
};

}  // namespace mbopt::lumped
