#include "worker/multibody/assembly.h"

#include <cmath>

#include "absl/strings/str_format.h"

namespace mbopt::multibody {
namespace {

// The assembly equations: the constraints plus, for each joint with an
// initial value and no driver, "coordinate = value" (row and Jacobian row by
// differences of the joint coordinate, which is exact enough for a
// condition that is only held, never differentiated again).
struct HeldCoordinate {
  int joint;
  double value;
};

std::vector<HeldCoordinate> HeldCoordinates(const Model& model, bool rates) {
  std::vector<bool> driven(model.joints.size(), false);
  for (const Driver& d : model.drivers) driven[static_cast<size_t>(d.joint)] = true;
  std::vector<HeldCoordinate> held;
  for (size_t j = 0; j < model.joints.size(); ++j) {
    const Joint& joint = model.joints[j];
    const std::optional<double>& value = rates ? joint.initial_rate : joint.initial_value;
    if (!driven[j] && value.has_value()) held.push_back({static_cast<int>(j), *value});
  }
  return held;
}

// Row of dq/dq-coordinate of a joint: central differences of the joint
// coordinate (it is a smooth function of two bodies' coordinates).
Eigen::RowVectorXd CoordinateGradient(const Mechanism& m, int joint, const Eigen::VectorXd& q) {
  constexpr double kStep = 1e-7;
  Eigen::RowVectorXd g(q.size());
  Eigen::VectorXd x = q;
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    x[i] = q[i] + kStep;
    const double plus = m.JointCoordinate(joint, x);
    x[i] = q[i] - kStep;
    const double minus = m.JointCoordinate(joint, x);
    x[i] = q[i];
    g[i] = (plus - minus) / (2 * kStep);
  }
  return g;
}

std::string WorstJoint(const Mechanism& m, const Eigen::VectorXd& phi) {
  Eigen::Index row = 0;
  phi.cwiseAbs().maxCoeff(&row);
  const int joint = m.joint_of_row(static_cast<int>(row));
  return absl::StrFormat("joint '%s'%s (residual %.3g)", m.model().joints[static_cast<size_t>(joint)].name,
                         m.is_driver_row(static_cast<int>(row)) ? "'s driver" : "", std::abs(phi[row]));
}

}  // namespace

std::string LockingJoint(const Mechanism& m, const Eigen::MatrixXd& phi_q) {
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(phi_q, Eigen::ComputeFullU);
  const Eigen::VectorXd left = svd.matrixU().col(svd.matrixU().cols() - 1);
  Eigen::Index row = 0;
  left.cwiseAbs().maxCoeff(&row);
  return absl::StrFormat("joint '%s'", m.model().joints[static_cast<size_t>(m.joint_of_row(static_cast<int>(row)))].name);
}

spec::AnalysisFailure SolvePositions(const Mechanism& m, double t, const AssemblyOptions& options, Eigen::VectorXd* q,
                                     int* iterations) {
  Eigen::VectorXd phi;
  Eigen::MatrixXd phi_q;
  for (*iterations = 0; *iterations <= options.max_iterations; ++*iterations) {
    if (options.budget != nullptr) {
      if (spec::AnalysisFailure f = options.budget->Check(t); !f.ok()) return f;
    }
    if (m.Constraints(t, *q, &phi) != 0) break;
    if (MaxAbs(phi) <= options.position_tolerance) return spec::AnalysisFailure::Ok();
    if (*iterations == options.max_iterations) break;
    m.ConstraintJacobian(t, *q, &phi_q);
    Eigen::PartialPivLU<Eigen::MatrixXd> lu(phi_q);
    const Eigen::VectorXd step = lu.solve(-phi);
    if (!step.allFinite()) break;
    *q += step;
  }
  return spec::AnalysisFailure::Of(
      spec::FailureKind::kAssembly,
      absl::StrFormat("the mechanism cannot close at t = %.6g s: %s", t,
                      phi.size() > 0 && phi.allFinite() ? WorstJoint(m, phi) : std::string("no finite position")));
}

Assembly Assemble(const Mechanism& m, double t, const AssemblyOptions& options) {
  Assembly out;
  const int n = m.num_coordinates();
  const std::vector<HeldCoordinate> held = HeldCoordinates(m.model(), false);
  const int rows = m.num_constraints() + static_cast<int>(held.size());
  Eigen::VectorXd q = m.InitialGuess();
  Eigen::VectorXd phi(rows), constraint_phi;
  Eigen::MatrixXd jac(rows, n), constraint_jac;
  double residual = 0.0;
  bool closed = false;
  int polished = 0;
  for (int it = 0; it <= options.max_iterations + options.polish_iterations; ++it) {
    if (options.budget != nullptr) {
      if (spec::AnalysisFailure f = options.budget->Check(t); !f.ok()) {
        out.failure = std::move(f);
        return out;
      }
    }
    m.Constraints(t, q, &constraint_phi);
    phi.head(m.num_constraints()) = constraint_phi;
    for (size_t k = 0; k < held.size(); ++k) {
      phi[m.num_constraints() + static_cast<Eigen::Index>(k)] = m.JointCoordinate(held[k].joint, q) - held[k].value;
    }
    residual = phi.allFinite() ? MaxAbs(phi) : INFINITY;
    if (residual <= options.position_tolerance && !closed) {
      closed = true;
      out.newton_iterations = it;
    }
    if (closed && (polished++ == options.polish_iterations || residual == 0.0)) break;
    m.ConstraintJacobian(t, q, &constraint_jac);
    jac.topRows(m.num_constraints()) = constraint_jac;
    for (size_t k = 0; k < held.size(); ++k) {
      jac.row(m.num_constraints() + static_cast<Eigen::Index>(k)) = CoordinateGradient(m, held[k].joint, q);
    }
    // Least squares with the minimum-norm step: free coordinates move as
    // little as possible, and redundant rows do not make the step singular.
    Eigen::VectorXd step = jac.completeOrthogonalDecomposition().solve(-phi);
    // Damping: halve the step while it makes the residual worse.
    double scale = 1.0;
    for (int halving = 0; halving < 20; ++halving) {
      const Eigen::VectorXd trial = q + scale * step;
      m.Constraints(t, trial, &constraint_phi);
      if (constraint_phi.allFinite() && MaxAbs(constraint_phi) < std::max(residual, 1e-300) * 1.0001) {
        break;
      }
      scale *= 0.5;
    }
    q += scale * step;
  }
  if (!closed) {
    out.failure = spec::AnalysisFailure::Of(
        spec::FailureKind::kAssembly,
        absl::StrFormat("the mechanism cannot be assembled at t = %.6g s: %s", t,
                        constraint_phi.size() > 0 && constraint_phi.allFinite() ? WorstJoint(m, constraint_phi)
                                                                                : std::string("no finite position")));
    return out;
  }
  m.ConstraintJacobian(t, q, &constraint_jac);
  // Degrees of freedom and redundant rows: a pivoted QR of Phi_q^T picks
  // independent constraint rows; the rest are redundant.
  // (Eigen's QR of an empty matrix is undefined: a free body has no rows.)
  out.degrees_of_freedom = n;
  if (m.num_constraints() > 0) {
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(constraint_jac.transpose());
    qr.setThreshold(options.rank_tolerance);
    qr.compute(constraint_jac.transpose());
    const int rank = static_cast<int>(qr.rank());
    out.degrees_of_freedom = n - rank;
    for (int k = rank; k < m.num_constraints(); ++k) {
      const int row = static_cast<int>(qr.colsPermutation().indices()[k]);
      const std::string name = m.model().joints[static_cast<size_t>(m.joint_of_row(row))].name;
      if (out.redundant.empty() || out.redundant.back() != name) out.redundant.push_back(name);
    }
  }
  // Velocities: Phi_q v = -Phi_t, held rates, minimum norm otherwise.
  const std::vector<HeldCoordinate> rates = HeldCoordinates(m.model(), true);
  Eigen::MatrixXd vel_jac(m.num_constraints() + static_cast<Eigen::Index>(rates.size()), n);
  Eigen::VectorXd vel_rhs(vel_jac.rows());
  Eigen::VectorXd phi_t;
  m.ConstraintTimeDerivative(t, q, &phi_t);
  vel_jac.topRows(m.num_constraints()) = constraint_jac;
  vel_rhs.head(m.num_constraints()) = -phi_t;
  for (size_t k = 0; k < rates.size(); ++k) {
    vel_jac.row(m.num_constraints() + static_cast<Eigen::Index>(k)) = CoordinateGradient(m, rates[k].joint, q);
    vel_rhs[m.num_constraints() + static_cast<Eigen::Index>(k)] = rates[k].value;
  }
  if (options.velocity_basis != nullptr && vel_jac.rows() > 0) {
    const Eigen::MatrixXd& basis = *options.velocity_basis;
    out.v = basis * Eigen::VectorXd((vel_jac * basis).completeOrthogonalDecomposition().solve(vel_rhs));
  } else {
    out.v = vel_jac.rows() > 0 ? Eigen::VectorXd(vel_jac.completeOrthogonalDecomposition().solve(vel_rhs))
                               : Eigen::VectorXd(Eigen::VectorXd::Zero(n));
  }
  out.q = std::move(q);
  return out;
}

}  // namespace mbopt::multibody
