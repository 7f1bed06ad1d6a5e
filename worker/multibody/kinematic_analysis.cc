#include "worker/multibody/kinematic_analysis.h"

#include "absl/strings/str_format.h"

namespace mbopt::multibody {
namespace {

struct State {
  double t = 0.0;
  Eigen::VectorXd q, v, a;
};

class DrivenMotion {
 public:
  DrivenMotion(const Mechanism& m, const KinematicOptions& o, KinematicCounters* c) : m_(m), options_(o), counters_(c) {}

  // Positions, velocities and accelerations at t from `q_guess`.
  spec::AnalysisFailure Solve(double t, Eigen::VectorXd q_guess, State* out) {
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
    return spec::AnalysisFailure::Ok();
  }

  // From `from` to t, halving the interval where Newton fails from the
  // extrapolated guess (a fast-moving driver between coarse instants).
  spec::AnalysisFailure Advance(const State& from, double t, int depth, State* out) {
    const double dt = t - from.t;
    spec::AnalysisFailure result = Solve(t, from.q + from.v * dt + 0.5 * dt * dt * from.a, out);
    // A lock is a property of the position, not of the guess: no retry.
    if (result.ok() || locked_ || depth >= options_.max_interval_halvings) {
      return result;
    }
    State middle;
    if (spec::AnalysisFailure f = Advance(from, from.t + 0.5 * dt, depth + 1, &middle); !f.ok()) return f;
    return Advance(middle, t, depth + 1, out);
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
  Eigen::MatrixXd phi_q_;
  Eigen::VectorXd phi_t_, gamma_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  bool locked_ = false;
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
    MotionSample sample{state.t, state.q, state.v, state.a, Eigen::VectorXd(), {}};
    if (options.inverse_dynamics) sample.lambda = motion.Multipliers(state);
    if (spec::AnalysisFailure f = at_instant(sample); !f.ok()) return f;
  }
  return spec::AnalysisFailure::Ok();
}

}  // namespace mbopt::multibody
