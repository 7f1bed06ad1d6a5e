#include "worker/solve/kinematic_solver.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_format.h"

namespace mbopt::solve {

namespace {

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Newton stops when every constraint is closed to this fraction of the
// largest link length (round-off of the squared-length form is ~1e-16).
constexpr double kPositionTolerance = 1e-12;
// A ratio of smallest to largest LU pivot below this means the mechanism is
// at (or numerically indistinguishable from) a singular, locking position.
// The constraint rows are scaled to unit gradients, so the ratio is a cheap
// stand-in for the reciprocal condition number.
constexpr double kSingularPivotRatio = 1e-10;

bool Singular(const Eigen::PartialPivLU<Eigen::MatrixXd>& lu) {
  const auto d = lu.matrixLU().diagonal().cwiseAbs();
  return !(d.minCoeff() > kSingularPivotRatio * d.maxCoeff());
}
// A Newton correction larger than this fraction of the largest link from a
// sub-step predictor means the iteration jumped (possibly to another branch):
// the sub-step is retried smaller.
constexpr double kMaxCorrectionFraction = 0.05;
// Sub-steps are halved down to this driver increment before giving up.
constexpr double kMinDriverStepRad = 1e-7;
constexpr int kStepNewtonIterations = 12;
constexpr int kAssemblyIterations = 100;

}  // namespace

Eigen::Vector2d LinkageState::LinkVector(const model::LinkageLink& link) const {
  return position_m[static_cast<size_t>(link.joint_b)] - position_m[static_cast<size_t>(link.joint_a)];
}

double LinkageState::LinkAngle(const model::LinkageLink& link) const {
  const Eigen::Vector2d d = LinkVector(link);
  return std::atan2(d.y(), d.x());
}

double LinkageState::LinkAngularVelocity(const model::LinkageLink& link) const {
  const Eigen::Vector2d d = LinkVector(link);
  const Eigen::Vector2d v = velocity_m_per_s[static_cast<size_t>(link.joint_b)] -
                            velocity_m_per_s[static_cast<size_t>(link.joint_a)];
  return Cross(d, v) / d.squaredNorm();
}

double LinkageState::LinkAngularAcceleration(const model::LinkageLink& link) const {
  const Eigen::Vector2d d = LinkVector(link);
  const Eigen::Vector2d v = velocity_m_per_s[static_cast<size_t>(link.joint_b)] -
                            velocity_m_per_s[static_cast<size_t>(link.joint_a)];
  const Eigen::Vector2d a = acceleration_m_per_s2[static_cast<size_t>(link.joint_b)] -
                            acceleration_m_per_s2[static_cast<size_t>(link.joint_a)];
  const double d2 = d.squaredNorm();
  return Cross(d, a) / d2 - 2.0 * d.dot(v) * Cross(d, v) / (d2 * d2);
}

KinematicSolver::KinematicSolver(const model::LinkageSystem& system) : sys_(system) {
  joint_dof_.assign(sys_.joints.size(), -1);
  for (size_t j = 0; j < sys_.joints.size(); ++j) {
    if (!sys_.joints[j].ground) {
      joint_dof_[j] = num_unknowns_;
      num_unknowns_ += 2;
    }
  }
  length_scale_m_ = 0.0;
  for (size_t i = 0; i < sys_.links.size(); ++i) {
    const model::LinkageLink& l = sys_.links[i];
    length_scale_m_ = std::max(length_scale_m_, l.length_m);
    if (l.both_ground || static_cast<int>(i) == sys_.driver.link) continue;
    constrained_links_.push_back(static_cast<int>(i));
  }
  if (!(length_scale_m_ > 0.0)) length_scale_m_ = 1.0;
  driven_length_m_ = sys_.links[static_cast<size_t>(sys_.driver.link)].length_m;
  const size_t nj = sys_.joints.size();
  state_.position_m.assign(nj, Eigen::Vector2d::Zero());
  state_.velocity_m_per_s.assign(nj, Eigen::Vector2d::Zero());
  state_.acceleration_m_per_s2.assign(nj, Eigen::Vector2d::Zero());
  for (size_t j = 0; j < nj; ++j) state_.position_m[j] = sys_.joints[j].position_m;
}

double KinematicSolver::DriverAngle(double t_s) const {
  return sys_.driver.start_angle_rad + sys_.driver.angular_velocity_rad_per_s * t_s;
}

void KinematicSolver::Residual(const Eigen::VectorXd& q, double angle, Eigen::VectorXd* r) const {
  auto pos = [&](int j) -> Eigen::Vector2d {
    const int k = joint_dof_[static_cast<size_t>(j)];
    return k < 0 ? sys_.joints[static_cast<size_t>(j)].position_m : Eigen::Vector2d(q(k), q(k + 1));
  };
  r->resize(num_unknowns_);
  int row = 0;
  for (int li : constrained_links_) {
    const model::LinkageLink& l = sys_.links[static_cast<size_t>(li)];
    const Eigen::Vector2d d = pos(l.joint_b) - pos(l.joint_a);
    (*r)(row++) = (d.squaredNorm() - l.length_m * l.length_m) / (2.0 * l.length_m);
  }
  const Eigen::Vector2d tip = pos(sys_.driver.pivot_joint) +
                              driven_length_m_ * Eigen::Vector2d(std::cos(angle), std::sin(angle));
  const Eigen::Vector2d err = pos(sys_.driver.driven_joint) - tip;
  (*r)(row++) = err.x();
  (*r)(row++) = err.y();
}

void KinematicSolver::Jacobian(const Eigen::VectorXd& q, Eigen::MatrixXd* jac) const {
  auto pos = [&](int j) -> Eigen::Vector2d {
    const int k = joint_dof_[static_cast<size_t>(j)];
    return k < 0 ? sys_.joints[static_cast<size_t>(j)].position_m : Eigen::Vector2d(q(k), q(k + 1));
  };
  jac->setZero(num_unknowns_, num_unknowns_);
  int row = 0;
  for (int li : constrained_links_) {
    const model::LinkageLink& l = sys_.links[static_cast<size_t>(li)];
    const Eigen::Vector2d g = (pos(l.joint_b) - pos(l.joint_a)) / l.length_m;
    const int kb = joint_dof_[static_cast<size_t>(l.joint_b)];
    const int ka = joint_dof_[static_cast<size_t>(l.joint_a)];
    if (kb >= 0) jac->block<1, 2>(row, kb) = g.transpose();
    if (ka >= 0) jac->block<1, 2>(row, ka) = -g.transpose();
    ++row;
  }
  const int kd = joint_dof_[static_cast<size_t>(sys_.driver.driven_joint)];
  (*jac)(row, kd) = 1.0;
  (*jac)(row + 1, kd + 1) = 1.0;
}

KinematicSolver::NewtonResult KinematicSolver::Newton(Eigen::VectorXd* q, double angle,
                                                      int max_iterations) {
  ++position_solves_;
  lu_at_solution_ = false;
  const double tol = kPositionTolerance * length_scale_m_;
  // The Jacobian is factorized at every iterate before the convergence test,
  // so that on convergence lu_ holds Phi_q at the solution for Complete().
  for (int it = 0;; ++it) {
    Jacobian(*q, &jac_);
    lu_.compute(jac_);
    Residual(*q, angle, &r_);
    if (r_.lpNorm<Eigen::Infinity>() <= tol) {
      lu_at_solution_ = true;
      return NewtonResult::kConverged;
    }
    if (it == max_iterations) return NewtonResult::kNoConvergence;
    if (Singular(lu_)) return NewtonResult::kSingular;
    ++newton_iterations_;
    r_ = -r_;
    dq_ = lu_.solve(r_);
    *q += dq_;
    if (!q->allFinite() || dq_.lpNorm<Eigen::Infinity>() > 0.5 * length_scale_m_) {
      return NewtonResult::kNoConvergence;
    }
  }
}

void KinematicSolver::ToState(const Eigen::VectorXd& q, LinkageState* s) const {
  const size_t nj = sys_.joints.size();
  s->position_m.resize(nj);
  s->velocity_m_per_s.assign(nj, Eigen::Vector2d::Zero());
  s->acceleration_m_per_s2.assign(nj, Eigen::Vector2d::Zero());
  for (size_t j = 0; j < nj; ++j) {
    const int k = joint_dof_[j];
    s->position_m[j] = k < 0 ? sys_.joints[j].position_m : Eigen::Vector2d(q(k), q(k + 1));
  }
}

void KinematicSolver::FromState(const LinkageState& s, Eigen::VectorXd* q,
                                Eigen::VectorXd* qdot) const {
  q->resize(num_unknowns_);
  qdot->resize(num_unknowns_);
  for (size_t j = 0; j < sys_.joints.size(); ++j) {
    const int k = joint_dof_[j];
    if (k < 0) continue;
    q->segment<2>(k) = s.position_m[j];
    qdot->segment<2>(k) = s.velocity_m_per_s[j];
  }
}

bool KinematicSolver::Complete(const Eigen::VectorXd& q, double t_s, LinkageState* s) {
  if (!lu_at_solution_) {
    Jacobian(q, &jac_);
    lu_.compute(jac_);
  }
  lu_at_solution_ = false;
  if (Singular(lu_)) return false;
  const double angle = DriverAngle(t_s);
  const double omega = sys_.driver.angular_velocity_rad_per_s;
  const Eigen::Vector2d e(std::cos(angle), std::sin(angle));
  const Eigen::Vector2d e_perp(-e.y(), e.x());
  const int nd = num_unknowns_;
  ToState(q, s);
  s->time_s = t_s;
  s->driver_angle_rad = angle;
  s->branch_sign = lu_.determinant() >= 0.0 ? 1.0 : -1.0;

  rhs_.setZero(nd);
  rhs_.segment<2>(nd - 2) = driven_length_m_ * omega * e_perp;
  qdot_ = lu_.solve(rhs_);
  for (size_t j = 0; j < sys_.joints.size(); ++j) {
    const int k = joint_dof_[j];
    if (k >= 0) s->velocity_m_per_s[j] = qdot_.segment<2>(k);
  }
  // Phi_q qddot = -(Phi_q qdot)_q qdot - Phi_tt.
  int row = 0;
  for (int li : constrained_links_) {
    const model::LinkageLink& l = sys_.links[static_cast<size_t>(li)];
    const Eigen::Vector2d dv = s->velocity_m_per_s[static_cast<size_t>(l.joint_b)] -
                               s->velocity_m_per_s[static_cast<size_t>(l.joint_a)];
    rhs_(row++) = -dv.squaredNorm() / l.length_m;
  }
  rhs_.segment<2>(nd - 2) = -driven_length_m_ * omega * omega * e;
  qdot_ = lu_.solve(rhs_);
  for (size_t j = 0; j < sys_.joints.size(); ++j) {
    const int k = joint_dof_[j];
    if (k >= 0) s->acceleration_m_per_s2[j] = qdot_.segment<2>(k);
  }
  return true;
}

std::string KinematicSolver::WorstConstraint(const Eigen::VectorXd& q, double angle) const {
  Eigen::VectorXd r;
  Residual(q, angle, &r);
  Eigen::Index worst = 0;
  r.cwiseAbs().maxCoeff(&worst);
  const int n_links = static_cast<int>(constrained_links_.size());
  if (worst < n_links) {
    const int li = constrained_links_[static_cast<size_t>(worst)];
    const model::LinkageLink& l = sys_.links[static_cast<size_t>(li)];
    return absl::StrFormat("%s, %s cannot be reached: its loop misses closure by %.4g m",
                           sys_.LinkLabel(li), sys_.JointLabel(l.joint_b),
                           std::abs(r(worst)));
  }
  return absl::StrFormat("%s cannot follow the driver of %s", sys_.JointLabel(sys_.driver.driven_joint),
                         sys_.LinkLabel(sys_.driver.link));
}

std::string KinematicSolver::NullMotionJoint() const {
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(jac_, Eigen::ComputeFullV);
  const Eigen::VectorXd v = svd.matrixV().col(num_unknowns_ - 1);
  int best = -1;
  double best_norm = -1.0;
  for (size_t j = 0; j < sys_.joints.size(); ++j) {
    const int k = joint_dof_[j];
    if (k < 0) continue;
    const double n = v.segment<2>(k).norm();
    if (n > best_norm) {
      best_norm = n;
      best = static_cast<int>(j);
    }
  }
  return best < 0 ? std::string("no joint") : sys_.JointLabel(best);
}

KinematicOutcome KinematicSolver::Start() {
  const int num_equations = static_cast<int>(constrained_links_.size()) + 2;
  if (num_equations != num_unknowns_) {
    const int dof = num_unknowns_ - num_equations;
    return KinematicOutcome::Of(spec::FailureKind::kInvalidModel, absl::StrFormat(
        "the driven linkage has %d degree(s) of freedom (%d joint coordinates, %d constraints); "
        "a driven mechanism needs exactly 0",
        dof, num_unknowns_, num_equations));
  }
  Eigen::VectorXd q(num_unknowns_);
  for (size_t j = 0; j < sys_.joints.size(); ++j) {
    const int k = joint_dof_[j];
    if (k >= 0) q.segment<2>(k) = sys_.joints[j].position_m;
  }
  const double angle = DriverAngle(0.0);
  // Damped Newton (least-squares steps) so that a poor initial guess still
  // assembles when a closed position exists.
  const double tol = kPositionTolerance * length_scale_m_;
  ++position_solves_;
  Residual(q, angle, &r_);
  double norm = r_.norm();
  bool converged = r_.lpNorm<Eigen::Infinity>() <= tol;
  for (int it = 0; it < kAssemblyIterations && !converged; ++it) {
    ++newton_iterations_;
    Jacobian(q, &jac_);
    const Eigen::VectorXd step = jac_.completeOrthogonalDecomposition().solve(-r_);
    double alpha = 1.0;
    bool improved = false;
    for (int k = 0; k < 30; ++k, alpha *= 0.5) {
      const Eigen::VectorXd trial = q + alpha * step;
      Residual(trial, angle, &r_);
      if (r_.allFinite() && r_.norm() < norm) {
        q = trial;
        norm = r_.norm();
        improved = true;
        break;
      }
    }
    if (!improved) break;
    converged = r_.lpNorm<Eigen::Infinity>() <= tol;
  }
  if (!converged) {
    return KinematicOutcome::Of(spec::FailureKind::kAssembly, absl::StrFormat(
        "the mechanism cannot assemble at t = 0 s (driver angle %.6g rad): %s", angle,
        WorstConstraint(q, angle)));
  }
  if (!Complete(q, 0.0, &state_)) {
    return KinematicOutcome::Of(spec::FailureKind::kAssembly, absl::StrFormat(
        "the mechanism is locked at t = 0 s (singular constraint Jacobian, a dead-centre "
        "position) at %s",
        NullMotionJoint()));
  }
  q_ = q;
  started_ = true;
  return {};
}

KinematicOutcome KinematicSolver::AdvanceTo(double t_s, std::vector<LinkageState>* trail) {
  if (!started_) return KinematicOutcome::Of(spec::FailureKind::kInvalidModel, "kinematic solver not started");
  const double omega = sys_.driver.angular_velocity_rad_per_s;
  if (omega == 0.0 || t_s <= state_.time_s) {
    state_.time_s = std::max(state_.time_s, t_s);
    return {};
  }
  double max_step_rad = kMaxDriverStepRad;
  Eigen::VectorXd q, qdot;
  LinkageState next;
  while (state_.time_s < t_s) {
    const double remaining_rad = std::abs(omega) * (t_s - state_.time_s);
    const bool last = remaining_rad <= max_step_rad;
    const double t_next = last ? t_s : state_.time_s + max_step_rad / std::abs(omega);
    FromState(state_, &q, &qdot);
    predicted_ = q + qdot * (t_next - state_.time_s);
    q = predicted_;
    const NewtonResult result = Newton(&q, DriverAngle(t_next), kStepNewtonIterations);
    const bool jumped =
        (q - predicted_).lpNorm<Eigen::Infinity>() > kMaxCorrectionFraction * length_scale_m_;
    if (jumped) lu_at_solution_ = false;
    enum class Rejection { kNone, kSingular, kBranch, kNoConvergence } why = Rejection::kNone;
    if (result == NewtonResult::kConverged && !jumped) {
      if (!Complete(q, t_next, &next)) {
        why = Rejection::kSingular;
      } else if (next.branch_sign != state_.branch_sign) {
        why = Rejection::kBranch;
      }
    } else {
      why = result == NewtonResult::kSingular ? Rejection::kSingular : Rejection::kNoConvergence;
    }
    if (why == Rejection::kNone) {
      state_ = next;
      q_ = q;
      if (trail) trail->push_back(state_);
      max_step_rad = std::min(kMaxDriverStepRad, 2.0 * max_step_rad);
      continue;
    }
    max_step_rad *= 0.5;
    if (max_step_rad >= kMinDriverStepRad) continue;
    // Give up: describe the lock at the last good state.
    FromState(state_, &q, &qdot);
    Jacobian(q, &jac_);
    const std::string joint = NullMotionJoint();
    if (why == Rejection::kBranch) {
      return KinematicOutcome::Of(spec::FailureKind::kAssembly, absl::StrFormat(
          "the mechanism changes assembly branch at t = %.6g s (driver angle %.6g rad): it "
          "passes a locking position at %s",
          state_.time_s, state_.driver_angle_rad, joint));
    }
    if (why == Rejection::kSingular) {
      return KinematicOutcome::Of(spec::FailureKind::kAssembly, absl::StrFormat(
          "the mechanism locks at t = %.6g s (driver angle %.6g rad): singular constraint "
          "Jacobian (dead-centre position) at %s",
          state_.time_s, state_.driver_angle_rad, joint));
    }
    return KinematicOutcome::Of(spec::FailureKind::kAssembly, absl::StrFormat(
        "the mechanism locks at t = %.6g s (driver angle %.6g rad): no closed position beyond "
        "it; the loop cannot close at %s (%s)",
        state_.time_s, state_.driver_angle_rad, joint, WorstConstraint(predicted_, DriverAngle(t_next))));
  }
  return {};
}

KinematicOutcome KinematicSolver::SolveFrom(const LinkageState& near, double t_s,
                                            LinkageState* out) {
  Eigen::VectorXd q, qdot;
  FromState(near, &q, &qdot);
  q += qdot * (t_s - near.time_s);
  const NewtonResult result = Newton(&q, DriverAngle(t_s), kStepNewtonIterations);
  if (result != NewtonResult::kConverged || !Complete(q, t_s, out) ||
      out->branch_sign != near.branch_sign) {
    return KinematicOutcome::Of(spec::FailureKind::kAssembly, absl::StrFormat(
        "no closed position of the linkage at t = %.6g s on the start branch", t_s));
  }
  return {};
}

}  // namespace mbopt::solve
