#include "worker/multibody/kinematic_analysis.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "absl/strings/str_format.h"

namespace mbopt::multibody {
namespace {

// Bisections that locate a lock between the last closed position and the
// first open one, down to this share of the time (1e-9 of 1 s).
constexpr int kLockBisections = 60;
constexpr double kLockTimeResolution = 1e-9;

struct State {
  double t = 0.0;
  Eigen::VectorXd q, v, a;
  // Sign of det(Phi_q): it changes only through a singular position, so a
  // change between two instants is a jump to another assembly branch or a
  // locking position passed in between.
  int branch_sign = 0;
};

// A Newton correction from the predicted positions larger than this share
// of the mechanism's size (or, for an angle, than this many radians: a link
// turned by it moves its end by that share of its length) means Newton
// jumped, possibly to another branch: the interval is halved.
constexpr double kMaxCorrectionFraction = 0.05;

// The mechanism's size: the largest distance between two joint points of one
// body (a link's length) or from a body's centre to one; 1 m if the joints
// all sit at the bodies' centres.
double LinkScale(const Model& model) {
  std::vector<std::vector<Eigen::Vector2d>> points(model.bodies.size());
  for (const Joint& j : model.joints) {
    for (const Point* p : {&j.a, &j.b}) {
      if (p->body != kGround) points[static_cast<size_t>(p->body)].push_back(p->local_m);
    }
  }
  double scale = 0.0;
  for (const std::vector<Eigen::Vector2d>& on_body : points) {
    for (size_t i = 0; i < on_body.size(); ++i) {
      scale = std::max(scale, on_body[i].norm());
      for (size_t k = 0; k < i; ++k) scale = std::max(scale, (on_body[i] - on_body[k]).norm());
    }
  }
  return scale > 0.0 ? scale : 1.0;
}

int DeterminantSign(const Eigen::PartialPivLU<Eigen::MatrixXd>& lu) {
  // From the pivots' signs, not their product (which may overflow or
  // underflow for a large mechanism).
  int sign = lu.permutationP().determinant();
  const auto pivots = lu.matrixLU().diagonal();
  for (Eigen::Index k = 0; k < pivots.size(); ++k) {
    if (pivots[k] < 0.0) sign = -sign;
  }
  return sign;
}

class DrivenMotion {
 public:
  DrivenMotion(const Mechanism& m, const KinematicOptions& o, KinematicCounters* c)
      : m_(m), options_(o), counters_(c), scale_m_(LinkScale(m.model())) {}

  // Positions, velocities and accelerations at t from `q_guess`.
  spec::AnalysisFailure Solve(double t, Eigen::VectorXd q_guess, State* out) {
    if (options_.budget != nullptr) {
      if (spec::AnalysisFailure f = options_.budget->ChargeSteps(1, t); !f.ok()) {
        budget_spent_ = true;
        return f;
      }
    }
    int iterations = 0;
    ++counters_->position_solves;
    spec::AnalysisFailure closed = SolvePositions(m_, t, options_.assembly, &q_guess, &iterations);
    counters_->newton_iterations += iterations;
    if (!closed.ok()) return closed;
    m_.ConstraintJacobian(t, q_guess, &phi_q_);
    lu_.compute(phi_q_);
    if (!(lu_.rcond() > options_.singular_rcond)) {
      locked_ = true;
      return spec::AnalysisFailure::Of(
          spec::FailureKind::kAssembly,
          absl::StrFormat("the mechanism locks at t = %.6g s: singular constraint Jacobian (a dead-centre "
                          "position) at %s",
                          t, LockingJoint(m_, phi_q_)));
    }
    m_.ConstraintTimeDerivative(t, q_guess, &phi_t_);
    out->t = t;
    out->v = lu_.solve(-phi_t_);
    m_.AccelerationRightSide(t, q_guess, out->v, &gamma_);
    out->a = lu_.solve(gamma_);
    out->q = std::move(q_guess);
    out->branch_sign = DeterminantSign(lu_);
    return spec::AnalysisFailure::Ok();
  }

  // From `from` to t, halving the interval where Newton fails from the
  // extrapolated guess or lands off the branch `from` is on (a fast-moving
  // driver between coarse instants): the answer is the one the continuous
  // motion gives.
  spec::AnalysisFailure Advance(const State& from, double t, int depth, State* out) {
    const double dt = t - from.t;
    const Eigen::VectorXd predicted = from.q + from.v * dt + 0.5 * dt * dt * from.a;
    spec::AnalysisFailure result = Solve(t, predicted, out);
    // A spent budget stays spent: halving the interval would only ask again.
    if (budget_spent_) return result;
    if (result.ok()) {
      const bool flipped = out->branch_sign != from.branch_sign;
      const double jump = Jump(out->q, predicted);
      if (!flipped && jump <= kMaxCorrectionFraction) return result;
      if (depth >= options_.max_interval_halvings) {
        if (flipped) {
          return spec::AnalysisFailure::Of(
              spec::FailureKind::kAssembly,
              absl::StrFormat("the mechanism changes assembly branch between t = %.9g s and %.9g s: it passes a "
                              "locking position (singular constraint Jacobian) in between, near %s",
                              from.t, t, LockingJoint(m_, phi_q_)));
        }
        return spec::AnalysisFailure::Of(
            spec::FailureKind::kAssembly,
            absl::StrFormat("the driven motion cannot be followed continuously between t = %.9g s and %.9g s: "
                            "the positions still jump by %.3g of the mechanism's size (%.3g m) over 1/%d of the "
                            "interval between instants",
                            from.t, t, jump, scale_m_, 1 << options_.max_interval_halvings));
      }
    } else if (locked_) {
      // A lock is a property of the position, not of the guess: no retry.
      return result;
    } else if (depth >= options_.max_interval_halvings) {
      // Newton fails however close the last closed position: the loop opens
      // between `from` and t (a crank driven past a lock). Bisect for where,
      // so that the time printed is the lock's whatever the step between
      // instants (a few Newton solves, once per analysis).
      State closed = from;
      double open_t = t;
      spec::AnalysisFailure open_failure = std::move(result);
      for (int k = 0; k < kLockBisections && open_t - closed.t > kLockTimeResolution * std::max(1.0, std::abs(t));
           ++k) {
        const double mid = 0.5 * (closed.t + open_t);
        const double h = mid - closed.t;
        State trial;
        spec::AnalysisFailure f = Solve(mid, closed.q + closed.v * h + 0.5 * h * h * closed.a, &trial);
        if (budget_spent_ || locked_) return f;
        if (f.ok() && trial.branch_sign == closed.branch_sign) {
          closed = std::move(trial);
        } else {
          open_t = mid;
          if (!f.ok()) open_failure = std::move(f);
        }
      }
      return spec::AnalysisFailure::Of(
          open_failure.kind, absl::StrFormat("the mechanism locks at t = %.6g s: no closed position beyond it; %s",
                                             closed.t, open_failure.reason));
    }
    State middle;
    if (spec::AnalysisFailure f = Advance(from, from.t + 0.5 * dt, depth + 1, &middle); !f.ok()) return f;
    return Advance(middle, t, depth + 1, out);
  }

  // The largest Newton correction from `predicted`, in shares of the
  // mechanism's size (angles in radians).
  double Jump(const Eigen::VectorXd& q, const Eigen::VectorXd& predicted) const {
    double jump = 0.0;
    for (Eigen::Index i = 0; i < q.size(); ++i) {
      const double correction = std::abs(q[i] - predicted[i]);
      jump = std::max(jump, i % 3 == 2 ? correction : correction / scale_m_);
    }
    return jump;
  }

  Eigen::VectorXd Multipliers(const State& s) {
    Eigen::MatrixXd mass;
    Eigen::VectorXd forces;
    m_.MassMatrix(s.q, &mass);
    m_.AppliedForces(s.t, s.q, s.v, &forces);
    // The factorization of Phi_q at this instant is the last one computed.
    return lu_.transpose().solve(forces - mass * s.a);
  }

 private:
  const Mechanism& m_;
  const KinematicOptions& options_;
  KinematicCounters* counters_;
  const double scale_m_;
  Eigen::MatrixXd phi_q_;
  Eigen::VectorXd phi_t_, gamma_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  bool locked_ = false;
  bool budget_spent_ = false;
};

}  // namespace

spec::AnalysisFailure RunKinematics(const Mechanism& m, const Eigen::VectorXd& q0, const std::vector<double>& times,
                                    const KinematicOptions& options, const MotionCallback& at_instant,
                                    KinematicCounters* counters) {
  if (m.num_constraints() != m.num_coordinates()) {
    return spec::AnalysisFailure::Of(
        spec::FailureKind::kInvalidModel,
        absl::StrFormat("a kinematic analysis needs as many independent constraints as coordinates (%d), got %d "
                        "rows: the driven mechanism is not determinate",
                        m.num_coordinates(), m.num_constraints()));
  }
  if (times.empty()) return spec::AnalysisFailure::Ok();
  DrivenMotion motion(m, options, counters);
  State state;
  if (spec::AnalysisFailure f = motion.Solve(times.front(), q0, &state); !f.ok()) return f;
  for (size_t i = 0; i < times.size(); ++i) {
    if (i > 0) {
      State next;
      if (spec::AnalysisFailure f = motion.Advance(state, times[i], 0, &next); !f.ok()) return f;
      state = std::move(next);
    }
    MotionSample sample{state.t, state.q, state.v, state.a, Eigen::VectorXd(), {}, state.branch_sign};
    if (options.inverse_dynamics) sample.lambda = motion.Multipliers(state);
    if (spec::AnalysisFailure f = at_instant(sample); !f.ok()) return f;
  }
  return spec::AnalysisFailure::Ok();
}

spec::AnalysisFailure SolveMotionNear(const Mechanism& m, const MotionSample& near, double t_s,
                                      const KinematicOptions& options, MotionSample* out,
                                      KinematicCounters* counters) {
  DrivenMotion motion(m, options, counters);
  const State from{near.t_s, near.q, near.v, near.a, near.branch_sign};
  State to;
  if (spec::AnalysisFailure f = motion.Advance(from, t_s, 0, &to); !f.ok()) return f;
  out->t_s = to.t;
  out->q = std::move(to.q);
  out->v = std::move(to.v);
  out->a = std::move(to.a);
  out->lambda.resize(0);
  out->branch_sign = to.branch_sign;
  return spec::AnalysisFailure::Ok();
}

}  // namespace mbopt::multibody
