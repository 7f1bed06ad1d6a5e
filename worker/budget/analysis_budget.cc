#include "worker/budget/analysis_budget.h"

#include <utility>

#include "absl/strings/str_format.h"

namespace mbopt::budget {

AnalysisBudget::AnalysisBudget(AnalysisClock clock, CancelRequested cancel_requested)
    : clock_(std::move(clock)), cancel_requested_(std::move(cancel_requested)) {}

AnalysisBudget AnalysisBudget::ForAnalysis(double max_wall_seconds, std::int64_t max_steps) const {
  AnalysisBudget budget(clock_, cancel_requested_);
  budget.deadline_s_ = deadline_s_;
  budget.max_wall_seconds_ = max_wall_seconds_;
  if (clock_ && max_wall_seconds > 0.0) {
    const double deadline_s = clock_() + max_wall_seconds;
    if (deadline_s < budget.deadline_s_) {
      budget.deadline_s_ = deadline_s;
      budget.max_wall_seconds_ = max_wall_seconds;
    }
  }
  budget.max_steps_ = max_steps > 0 ? max_steps : 0;
  return budget;
}

bool AnalysisBudget::Exhausted() const {
  if (cancel_requested_ && cancel_requested_()) return true;
  return has_deadline() && clock_() > deadline_s_;
}

spec::AnalysisFailure AnalysisBudget::Check(double t_s) const {
  if (cancel_requested_ && cancel_requested_()) {
    return spec::AnalysisFailure::Of(spec::FailureKind::kCancelled,
                                     absl::StrFormat("the analysis was cancelled at t = %.6g s", t_s));
  }
  if (has_deadline() && clock_() > deadline_s_) {
    return spec::AnalysisFailure::Of(
        spec::FailureKind::kTimeLimit,
        absl::StrFormat("the wall-time limit of %g s (integrator.max_wall_seconds) was reached at t = %.6g s",
                        max_wall_seconds_, t_s));
  }
  return spec::AnalysisFailure::Ok();
}

spec::AnalysisFailure AnalysisBudget::ChargeSteps(std::int64_t steps, double t_s) {
  steps_used_ += steps;
  if (max_steps_ > 0 && steps_used_ > max_steps_) {
    return spec::AnalysisFailure::Of(
        spec::FailureKind::kTimeLimit,
        absl::StrFormat("the step budget of %d steps (integrator.max_steps) was spent at t = %.6g s", max_steps_,
                        t_s));
  }
  return Check(t_s);
}

}  // namespace mbopt::budget
