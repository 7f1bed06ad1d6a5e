#include "server/slp/options.h"

#include <cmath>
#include <string>

#include "absl/strings/str_cat.h"

namespace mbopt::slp {
namespace {

absl::Status Bad(const char* field, double value, const char* rule) {
  return absl::InvalidArgumentError(
      absl::StrCat("SlpOptions.", field, " = ", value, ": ", rule));
}

}  // namespace

absl::Status SlpOptions::Validate() const {
  struct Positive {
    const char* name;
    double value;
  };
  const Positive positives[] = {
      {"initial_move_limit", initial_move_limit},
      {"move_limit_floor_fraction_of_range", move_limit_floor_fraction_of_range},
      {"min_move_limit", min_move_limit},
      {"max_move_limit", max_move_limit},
      {"finite_difference_relative_step", finite_difference_relative_step},
      {"reject_max_approximation_error", reject_max_approximation_error},
      {"reject_max_violation", reject_max_violation},
      {"widen_max_approximation_error", widen_max_approximation_error},
      {"widen_max_violation", widen_max_violation},
      {"narrow_max_approximation_error", narrow_max_approximation_error},
      {"narrow_max_violation", narrow_max_violation},
      {"oscillation_objective_change", oscillation_objective_change},
      {"convergence_objective_tolerance", convergence_objective_tolerance},
      {"convergence_violation_tolerance", convergence_violation_tolerance},
      {"convergence_optimality_tolerance", convergence_optimality_tolerance},
      {"infeasibility_penalty", infeasibility_penalty},
      {"infeasibility_tolerance", infeasibility_tolerance},
      {"objective_magnitude_floor", objective_magnitude_floor},
  };
  for (const Positive& p : positives) {
    if (!std::isfinite(p.value) || p.value <= 0.0) {
      return Bad(p.name, p.value, "must be finite and > 0");
    }
  }
  if (objective_target.has_value() && !std::isfinite(*objective_target)) {
    return Bad("objective_target", *objective_target, "must be finite");
  }
  if (min_move_limit > max_move_limit) {
    return absl::InvalidArgumentError(
        absl::StrCat("SlpOptions.min_move_limit = ", min_move_limit,
                     " exceeds max_move_limit = ", max_move_limit));
  }
  if (initial_move_limit < min_move_limit || initial_move_limit > max_move_limit) {
    return absl::InvalidArgumentError(absl::StrCat(
        "SlpOptions.initial_move_limit = ", initial_move_limit, " is outside [min_move_limit, ",
        "max_move_limit] = [", min_move_limit, ", ", max_move_limit, "]"));
  }
  if (move_limit_floor_fraction_of_range > 1.0) {
    return Bad("move_limit_floor_fraction_of_range", move_limit_floor_fraction_of_range,
               "must be <= 1");
  }
  if (finite_difference_relative_step > 0.1) {
    return Bad("finite_difference_relative_step", finite_difference_relative_step,
               "must be <= 0.1 (a larger step is no derivative)");
  }
  if (!std::isfinite(screening_threshold) || screening_threshold > 0.0) {
    return Bad("screening_threshold", screening_threshold,
               "must be finite and <= 0 (a positive threshold would drop violated constraints)");
  }
  if (!std::isfinite(objective_screening_threshold) || objective_screening_threshold > 0.0) {
    return Bad("objective_screening_threshold", objective_screening_threshold,
               "must be finite and <= 0");
  }
  if (!(widen_max_approximation_error <= narrow_max_approximation_error &&
        narrow_max_approximation_error <= reject_max_approximation_error)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "SlpOptions approximation-error thresholds must satisfy widen <= narrow <= reject; got ",
        widen_max_approximation_error, ", ", narrow_max_approximation_error, ", ",
        reject_max_approximation_error));
  }
  if (!(widen_max_violation <= narrow_max_violation &&
        narrow_max_violation <= reject_max_violation)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "SlpOptions violation thresholds must satisfy widen <= narrow <= reject; got ",
        widen_max_violation, ", ", narrow_max_violation, ", ", reject_max_violation));
  }
  if (max_cycles < 1) return Bad("max_cycles", max_cycles, "must be >= 1");
  if (max_rejections_per_cycle < 1) {
    return Bad("max_rejections_per_cycle", max_rejections_per_cycle, "must be >= 1");
  }
  if (finite_difference != FiniteDifferenceScheme::kForward &&
      finite_difference != FiniteDifferenceScheme::kCentral) {
    return absl::InvalidArgumentError("SlpOptions.finite_difference: unknown scheme");
  }
  return absl::OkStatus();
}

}  // namespace mbopt::slp
