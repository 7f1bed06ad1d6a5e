// Settings of the SLP method. Defaults are the thresholds of METHOD.md
// section 3 (Etman et al. 1994); every field is documented in docs/method.md.
#pragma once

#include <optional>

#include "absl/status/status.h"

namespace mbopt::slp {

enum class FiniteDifferenceScheme {
  kForward,  // n extra analyses per cycle, O(h) error (the report's choice)
  kCentral,  // 2n extra analyses per cycle, O(h^2) error
};

struct SlpOptions {
  // Move limits (section 3): relative factor f_i, box |x_i - x0_i| <= f_i |x0_i|.
  double initial_move_limit = 0.2;
  // Floor of the box half-width, as a fraction of (upper - lower), for
  // variables at or near zero.
  double move_limit_floor_fraction_of_range = 0.01;
  double min_move_limit = 1e-6;   // f_i is never shrunk below this
  double max_move_limit = 1.0;    // nor widened above this

  // Constraint screening: rows whose normalized value is below this are left
  // out of the cycle's LP (-0.3: "within 30 % of the limit or violated").
  double screening_threshold = -0.3;

  // Objective terms of a min-max objective are screened the same way, with
  // (f_j - F) / max(|F|, objective_magnitude_floor) against this threshold.
  // Both screens also keep every row whose linearization could reach its
  // limit (the current maximum, for objective terms) inside the move-limit
  // box, so a screened-out row is redundant in the LP: screening changes the
  // LP's size, never its solution.
  double objective_screening_threshold = -0.3;

  // Finite differences, in scaled variables: step h_i = relative_step *
  // max(|x_i|, typical_magnitude_i) where typical_magnitude_i = (upper_i -
  // lower_i) * move_limit_floor_fraction_of_range guards x_i = 0; a step that
  // would leave the bounds is taken backwards (forward scheme) or shrunk to
  // fit (central scheme; below half the step it falls back to one side).
  // A failed perturbation is retried once on the other side (or with half
  // the step when the other side is out of bounds); if that fails too, the
  // variable is held fixed for the cycle.
  FiniteDifferenceScheme finite_difference = FiniteDifferenceScheme::kForward;
  double finite_difference_relative_step = 1e-4;

  // Gradients come with the analyses (the simulator's sensitivities): each
  // cycle then asks only for x0 and no perturbation, and every request
  // carries want_gradients. A result without usable gradients (missing,
  // NaN) falls back to the finite differences above for that cycle.
  bool analyses_provide_gradients = false;

  // Acceptance and strategy thresholds (section 3).
  double reject_max_approximation_error = 0.40;
  double reject_max_violation = 0.10;
  double widen_max_approximation_error = 0.10;
  double widen_max_violation = 0.05;
  double narrow_max_approximation_error = 0.25;
  double narrow_max_violation = 0.075;
  double oscillation_objective_change = 0.02;

  // Convergence: |F* - F0| / |F0| < objective_tolerance and maxg <
  // violation_tolerance (the report's test), and first-order optimality:
  // the accepted cycle's KKT residual (cycle_lp.h, OptimalityResidual) below
  // optimality_tolerance. The report's test alone bounds the last step, not
  // the distance to the optimum; the residual says whether the
  // linearization still offers a descent that the move limits cut off.
  double convergence_objective_tolerance = 0.005;
  double convergence_violation_tolerance = 0.005;
  double convergence_optimality_tolerance = 0.005;
  // A value of F the user calls good enough: an accepted design with F at
  // or below it and maxg below violation_tolerance ends the run converged,
  // whatever the tests above say. For objectives whose optimum is known,
  // such as a distance to targets that can be met (F = 0), where the
  // relative tests have no scale. Absent: no such stop.
  std::optional<double> objective_target;

  // Penalty on the infeasibility variable s, relative to the objective's scale.
  double infeasibility_penalty = 1e3;
  // The LP counts as feasible ("feas") when s <= this (s is a normalized
  // constraint violation).
  double infeasibility_tolerance = 1e-7;
  // |F| below this counts as zero in relative objective measures (e_o, the
  // convergence and oscillation tests): they divide by max(|F|, floor).
  double objective_magnitude_floor = 1e-10;

  int max_cycles = 50;
  // Consecutive rejections of one cycle's trial points before the cycle gives
  // up (the move limits are then tiny; the job ends "stalled").
  int max_rejections_per_cycle = 20;

  absl::Status Validate() const;
};

}  // namespace mbopt::slp
