// The wall-time limit of a linkage analysis (IntegratorSettings::
// max_wall_seconds) for its kinematic sweep, on the process' own clock. Only
// the linkage solvers use it: they predate the analysis budget
// (worker/budget/analysis_budget.h), which every other analysis runs
// within, and this goes with them when the multibody front end replaces
// them.
#pragma once

#include <chrono>

#include "absl/strings/str_format.h"
#include "spec/analysis_outcome.h"

namespace mbopt::solve {

class WallTimeBudget {
 public:
  // <= 0: no limit.
  explicit WallTimeBudget(double max_seconds)
      : max_seconds_(max_seconds), start_(std::chrono::steady_clock::now()) {}

  bool Exceeded() const {
    return max_seconds_ > 0.0 &&
           std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count() > max_seconds_;
  }

  // The failure to report when Exceeded() at instant `t_s`.
  spec::AnalysisFailure Failure(double t_s) const {
    return spec::AnalysisFailure::Of(
        spec::FailureKind::kTimeLimit,
        absl::StrFormat("the wall-time limit of %g s (integrator.max_wall_seconds) was reached at t = %.6g s",
                        max_seconds_, t_s));
  }

 private:
  double max_seconds_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace mbopt::solve
