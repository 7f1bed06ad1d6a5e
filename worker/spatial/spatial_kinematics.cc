#include "worker/spatial/spatial_kinematics.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_format.h"

namespace mbopt::spatial {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr int kBlock = SpatialSystem::kCoordinatesPerBody;
constexpr int kMaxNewtonIterations = 25;

// A Newton correction of the predicted positions larger than this share of
// the mechanism's size, or of an Euler parameter larger than this (about
// twice as many radians), means Newton jumped, possibly to another branch:
// the interval is halved.
constexpr double kMaxCorrectionFraction = 0.05;

struct State {
  double t = 0.0;
  VectorXd q, v, a;
  int branch_sign = 0;  // sign of det(Phi_q); 0 when Phi_q is not square
};

// The mechanism's size: the largest distance of a joint frame from its
// body's centre of mass; 1 m if every joint sits at a centre.
double MechanismScale(const Model& model) {
  double scale = 0.0;
  for (const Joint& j : model.joints) {
    for (const Frame* f : {&j.a, &j.b}) {
      if (f->body != kGround) scale = std::max(scale, f->position_m.norm());
    }
  }
  return scale > 0.0 ? scale : 1.0;
}

// The residuals in their own units (the unit-norm rows without their scale).
double Residual(const SpatialSystem& system, const VectorXd& phi) {
  const int bodies = static_cast<int>(system.model().bodies.size());
  double r = phi.size() > bodies ? phi.tail(phi.size() - bodies).cwiseAbs().maxCoeff() : 0.0;
  if (bodies > 0) r = std::max(r, phi.head(bodies).cwiseAbs().maxCoeff() / SpatialSystem::kNormRowScale);
  return r;
}

// Phi_q factored once per solve: LU with partial pivoting when square (and
// the sign of its determinant), otherwise a least-squares decomposition.
class JacobianSolver {
 public:
  bool Factor(const MatrixXd& phi_q, double singular_rcond) {
    square_ = phi_q.rows() == phi_q.cols();
    if (square_) {
      lu_.compute(phi_q);
      if (!(lu_.rcond() > singular_rcond)) return false;
      sign_ = lu_.permutationP().determinant();
      const auto pivots = lu_.matrixLU().diagonal();
      for (Eigen::Index k = 0; k < pivots.size(); ++k) {
        if (pivots[k] < 0.0) sign_ = -sign_;
      }
      return true;
    }
    cod_.compute(phi_q);
    cod_.setThreshold(1e-9);
    sign_ = 0;
    return cod_.rank() == phi_q.cols();
  }
  VectorXd Solve(const VectorXd& rhs) const { return square_ ? VectorXd(lu_.solve(rhs)) : VectorXd(cod_.solve(rhs)); }
  int sign() const { return sign_; }

 private:
  bool square_ = true;
  int sign_ = 0;
  Eigen::PartialPivLU<MatrixXd> lu_;
  Eigen::CompleteOrthogonalDecomposition<MatrixXd> cod_;
};

class Solver {
 public:
  Solver(const SpatialSystem& system, const SpatialKinematicOptions& options, SpatialKinematicCounters* counters)
      : system_(system), options_(options), counters_(counters), scale_m_(MechanismScale(system.model())) {}

  // Positions at t from `guess`, then velocities and accelerations.
  spec::AnalysisFailure Solve(double t, const VectorXd& guess, State* out) {
    ++counters_->position_solves;
    if (options_.budget != nullptr) {
      if (spec::AnalysisFailure f = options_.budget->Check(t); !f.ok()) return f;
    }
    out->t = t;
    out->q = guess;
    VectorXd phi;
    MatrixXd phi_q;
    for (int iteration = 0;; ++iteration) {
      if (system_.Constraints(t, out->q, &phi) != 0) return NotFinite(t);
      if (Residual(system_, phi) <= options_.assembly.position_tolerance) break;
      if (iteration == kMaxNewtonIterations) return NotClosed(t, phi);
      if (system_.ConstraintJacobian(t, out->q, &phi_q) != 0) return NotFinite(t);
      if (!jacobian_.Factor(phi_q, options_.singular_rcond)) return Locked(t);
      out->q -= jacobian_.Solve(phi);
      ++counters_->newton_iterations;
    }
    VectorXd phi_t, gamma;
    if (system_.ConstraintJacobian(t, out->q, &phi_q) != 0 || system_.ConstraintTimeDerivative(t, out->q, &phi_t) != 0) {
      return NotFinite(t);
    }
    if (!jacobian_.Factor(phi_q, options_.singular_rcond)) return Locked(t);
    out->branch_sign = jacobian_.sign();
    out->v = jacobian_.Solve(-phi_t);
    if (system_.AccelerationRightSide(t, out->q, out->v, &gamma) != 0) return NotFinite(t);
    out->a = jacobian_.Solve(gamma);
    if (!out->v.allFinite() || !out->a.allFinite()) return NotFinite(t);
    return spec::AnalysisFailure::Ok();
  }

  // From the state `from` to time t, halving the interval where the step
  // would leave the branch.
  spec::AnalysisFailure Advance(const State& from, double t, State* out) {
    State at = from;
    double step = t - from.t;
    int halvings = 0;
    while (at.t < t) {
      const double next = std::min(t, at.t + step);
      const double h = next - at.t;
      const VectorXd predicted = at.q + h * at.v + 0.5 * h * h * at.a;
      State trial;
      spec::AnalysisFailure f = Solve(next, predicted, &trial);
      const bool jumped = f.ok() && (Jumped(predicted, trial.q) || (trial.branch_sign != 0 && at.branch_sign != 0 &&
                                                                   trial.branch_sign != at.branch_sign));
      if (f.ok() && !jumped) {
        at = std::move(trial);
        continue;
      }
      if (f.kind == spec::FailureKind::kTimeLimit || f.kind == spec::FailureKind::kCancelled) return f;
      if (halvings == options_.max_interval_halvings) {
        if (!f.ok()) return f;
        return spec::AnalysisFailure::Of(
            spec::FailureKind::kAssembly,
            absl::StrFormat("the driven mechanism leaves its assembly branch between t = %.6g s and %.6g s "
                            "(a locking or dead-centre position in between, or drivers that demand another "
                            "assembly): check the drivers' ranges",
                            at.t, next));
      }
      ++halvings;
      step *= 0.5;
    }
    *out = std::move(at);
    return spec::AnalysisFailure::Ok();
  }

 private:
  bool Jumped(const VectorXd& predicted, const VectorXd& solved) const {
    for (int body = 0; body * kBlock < predicted.size(); ++body) {
      const int at = kBlock * body;
      if ((solved.segment<3>(at) - predicted.segment<3>(at)).norm() > kMaxCorrectionFraction * scale_m_) return true;
      if ((solved.segment<4>(at + 3) - predicted.segment<4>(at + 3)).norm() > kMaxCorrectionFraction) return true;
    }
    return false;
  }
  static spec::AnalysisFailure NotFinite(double t) {
    return spec::AnalysisFailure::Of(spec::FailureKind::kNonFiniteValue,
                                     absl::StrFormat("the constraint equations are not finite at t = %.6g s", t));
  }
  spec::AnalysisFailure NotClosed(double t, const VectorXd& phi) const {
    VectorXd unscaled = phi;
    unscaled.head(static_cast<int>(system_.model().bodies.size())) /= SpatialSystem::kNormRowScale;
    int row = 0;
    unscaled.cwiseAbs().maxCoeff(&row);
    return spec::AnalysisFailure::Of(
        spec::FailureKind::kAssembly,
        absl::StrFormat("the driven mechanism does not assemble at t = %.6g s: %s is off by %.3g after %d Newton "
                        "iterations",
                        t, system_.RowOwner(row), unscaled[row], kMaxNewtonIterations));
  }
  static spec::AnalysisFailure Locked(double t) {
    return spec::AnalysisFailure::Of(
        spec::FailureKind::kAssembly,
        absl::StrFormat("the driven mechanism locks at t = %.6g s: the constraint Jacobian is singular (a dead "
                        "centre, or drivers that fight each other)",
                        t));
  }

  const SpatialSystem& system_;
  const SpatialKinematicOptions& options_;
  SpatialKinematicCounters* counters_;
  const double scale_m_;
  JacobianSolver jacobian_;
};

}  // namespace

spec::AnalysisFailure RunSpatialKinematics(const SpatialSystem& system, const VectorXd& q0,
                                           const std::vector<double>& times_s, const SpatialKinematicOptions& options,
                                           const multibody::MotionCallback& at_instant,
                                           SpatialKinematicCounters* counters) {
  if (times_s.empty()) return spec::AnalysisFailure::Ok();
  Solver solver(system, options, counters);
  State state;
  if (spec::AnalysisFailure f = solver.Solve(times_s.front(), q0, &state); !f.ok()) return f;
  for (size_t k = 0; k < times_s.size(); ++k) {
    if (k > 0) {
      State next;
      if (spec::AnalysisFailure f = solver.Advance(state, times_s[k], &next); !f.ok()) return f;
      state = std::move(next);
    }
    multibody::MotionSample sample;
    sample.t_s = state.t;
    sample.q = state.q;
    sample.v = state.v;
    sample.a = state.a;
    sample.branch_sign = state.branch_sign;
    if (spec::AnalysisFailure f = at_instant(sample); !f.ok()) return f;
  }
  return spec::AnalysisFailure::Ok();
}

VectorXd Multipliers(const SpatialSystem& system, double t, const VectorXd& q, const VectorXd& v, const VectorXd& a) {
  MatrixXd mass, phi_q;
  VectorXd forces;
  if (system.MassMatrix(q, &mass) != 0 || system.AppliedForces(t, q, v, &forces) != 0 ||
      system.ConstraintJacobian(t, q, &phi_q) != 0) {
    return VectorXd();
  }
  const Eigen::CompleteOrthogonalDecomposition<MatrixXd> cod(phi_q.transpose());
  VectorXd lambda = cod.solve(forces - mass * a);
  return lambda.allFinite() ? lambda : VectorXd();
}

}  // namespace mbopt::spatial
