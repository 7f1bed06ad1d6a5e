#include "server/slp/move_limit_strategy.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "common/check.h"

namespace mbopt::slp {

const char* MoveLimitBranchName(MoveLimitBranch branch) {
  switch (branch) {
    case MoveLimitBranch::kRejected:
      return "rejected";
    case MoveLimitBranch::kOscillation:
      return "oscillation";
    case MoveLimitBranch::kNoImprovement:
      return "no_improvement";
    case MoveLimitBranch::kOnMoveLimitWiden:
      return "on_move_limit_widen";
    case MoveLimitBranch::kOnMoveLimitNarrow:
      return "on_move_limit_narrow";
    case MoveLimitBranch::kOnMoveLimitKeep:
      return "on_move_limit_keep";
    case MoveLimitBranch::kPoorApproximationNarrow:
      return "poor_approximation_narrow";
    case MoveLimitBranch::kUnchanged:
      return "unchanged";
  }
  return "unknown";
}

double RelativeObjectiveChange(double objective_x0, double objective_trial, double floor) {
  return std::abs(objective_trial - objective_x0) / std::max(std::abs(objective_x0), floor);
}

MoveLimitDecision ApplyMoveLimitStrategy(const SlpOptions& o, const MoveLimitInput& in) {
  const Eigen::Index n = in.move_limits.size();
  MBOPT_CHECK(in.dx_new.size() == n || in.trial_failed, "dx_new has the wrong size");
  MBOPT_CHECK(static_cast<Eigen::Index>(in.on_move_limit.size()) == n || in.trial_failed,
              "on_move_limit has the wrong size");
  MBOPT_CHECK(static_cast<Eigen::Index>(in.on_bound.size()) == n || in.trial_failed,
              "on_bound has the wrong size");
  MBOPT_CHECK(in.dx_old.size() == 0 || in.dx_old.size() == n, "dx_old has the wrong size");

  MoveLimitDecision out;
  out.move_limits_next = in.move_limits;
  out.branches.assign(static_cast<size_t>(n), MoveLimitBranch::kUnchanged);
  auto clamp = [&](double f) { return std::clamp(f, o.min_move_limit, o.max_move_limit); };

  const double maxfout = in.max_approximation_error;
  const double maxg = in.max_violation;
  const bool feas = in.lp_feasible;

  std::string reject;
  if (in.trial_failed) {
    reject = "trial analysis failed";
  } else if (maxfout > o.reject_max_approximation_error) {
    reject = absl::StrCat("approximation error ", maxfout, " > ",
                          o.reject_max_approximation_error);
  } else if (maxg > o.reject_max_violation && feas) {
    reject = absl::StrCat("constraint violation ", maxg, " > ", o.reject_max_violation,
                          " although the LP was feasible");
  }
  if (!reject.empty()) {
    out.accept = false;
    out.rejection_reason = std::move(reject);
    for (Eigen::Index i = 0; i < n; ++i) {
      out.move_limits_next[i] = clamp(kRejectShrinkFactor * in.move_limits[i]);
      out.branches[i] = MoveLimitBranch::kRejected;
    }
    return out;
  }

  out.accept = true;
  const double relative_change =
      RelativeObjectiveChange(in.objective_x0, in.objective_trial, o.objective_magnitude_floor);
  const double dF_new = in.objective_trial - in.objective_x0;
  const bool objective_alternates =
      in.previous_objective_change.has_value() && dF_new * *in.previous_objective_change < 0.0;
  const bool objective_stalls_or_alternates =
      relative_change < o.oscillation_objective_change || objective_alternates;
  const bool poor = maxfout > o.narrow_max_approximation_error ||
                    (maxg > o.narrow_max_violation && feas);
  const bool good = maxfout < o.widen_max_approximation_error &&
                    (maxg < o.widen_max_violation || !feas);

  for (Eigen::Index i = 0; i < n; ++i) {
    const double f = in.move_limits[i];
    const double dx_old = in.dx_old.size() == n ? in.dx_old[i] : 0.0;
    MoveLimitBranch branch = MoveLimitBranch::kUnchanged;
    double next = f;
    if (in.dx_new[i] * dx_old < 0.0 && objective_stalls_or_alternates && feas) {
      branch = MoveLimitBranch::kOscillation;
      next = kOscillationFactor * f;
    } else if (in.objective_trial > in.objective_x0 && feas) {
      branch = MoveLimitBranch::kNoImprovement;
      next = kNoImprovementFactor * f;
    } else if (in.on_move_limit[i] && !in.on_bound[i]) {
      if (good) {
        branch = MoveLimitBranch::kOnMoveLimitWiden;
        next = kWidenFactor * f;
      } else if (poor) {
        branch = MoveLimitBranch::kOnMoveLimitNarrow;
        next = kNarrowFactor * f;
      } else {
        branch = MoveLimitBranch::kOnMoveLimitKeep;
      }
    } else if (poor && !in.on_bound[i]) {
      branch = MoveLimitBranch::kPoorApproximationNarrow;
      next = kNarrowFactor * f;
    }
    out.branches[i] = branch;
    out.move_limits_next[i] = clamp(next);
  }
  return out;
}

}  // namespace mbopt::slp
