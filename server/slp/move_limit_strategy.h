// The acceptance test and adaptive move-limit strategy of METHOD.md section 3
// (Etman et al. 1994), as a pure function of one trial point's measures.
// Every branch of the pseudo-code is one MoveLimitBranch, so each can be
// tested on its own and recorded per variable.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "server/slp/options.h"

namespace mbopt::slp {

// The factors of METHOD.md section 3.
inline constexpr double kRejectShrinkFactor = 0.75;
inline constexpr double kOscillationFactor = 0.5;
inline constexpr double kNoImprovementFactor = 0.75;
inline constexpr double kWidenFactor = 4.0 / 3.0;
inline constexpr double kNarrowFactor = 0.75;

enum class MoveLimitBranch {
  kRejected,                 // trial rejected: f_i = 3/4 f_i for all i
  kOscillation,              // dx_new*dx_old < 0 and stalling/alternating F: f_i / 2
  kNoImprovement,            // F* > F0 with a feasible LP: 3/4 f_i
  kOnMoveLimitWiden,         // on its move limit, good approximation: 4/3 f_i
  kOnMoveLimitNarrow,        // on its move limit, poor approximation: 3/4 f_i
  kOnMoveLimitKeep,          // on its move limit, neither good nor poor
  kPoorApproximationNarrow,  // inside the box, poor approximation: 3/4 f_i
  kUnchanged,                // none of the above
};

const char* MoveLimitBranchName(MoveLimitBranch branch);

struct MoveLimitInput {
  double max_approximation_error = 0;  // maxfout
  double max_violation = 0;            // maxg at x* (normalized, > 0 violated)
  bool lp_feasible = true;             // feas
  // The analysis of x* failed: no measures exist, the trial is rejected.
  bool trial_failed = false;
  double objective_x0 = 0;     // F0
  double objective_trial = 0;  // F*
  // F* - F0 of the previous accepted cycle; none in the first cycle.
  std::optional<double> previous_objective_change;
  Eigen::VectorXd dx_new;  // x* - x0
  Eigen::VectorXd dx_old;  // of the previous accepted cycle; empty if none
  std::vector<bool> on_move_limit;  // mvlimact(i)
  std::vector<bool> on_bound;       // boundact(i)
  Eigen::VectorXd move_limits;      // f_i used for this LP
};

struct MoveLimitDecision {
  bool accept = false;
  std::string rejection_reason;     // empty when accepted
  Eigen::VectorXd move_limits_next; // clamped to [min_move_limit, max_move_limit]
  std::vector<MoveLimitBranch> branches;  // per variable
};

// |F* - F0| / max(|F0|, floor): the relative objective change of METHOD.md.
double RelativeObjectiveChange(double objective_x0, double objective_trial, double floor);

MoveLimitDecision ApplyMoveLimitStrategy(const SlpOptions& options, const MoveLimitInput& in);

}  // namespace mbopt::slp
