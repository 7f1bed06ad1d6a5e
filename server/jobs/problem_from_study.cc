#include "server/jobs/problem_from_study.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "spec/layout.h"

namespace mbopt::jobs {
namespace {

absl::Status InStudy(const spec::Study& study, const absl::Status& status) {
  if (status.ok()) return status;
  return absl::Status(status.code(), absl::StrCat(study.source_file.empty() ? study.name : study.source_file,
                                                  ": ", status.message()));
}

}  // namespace

absl::StatusOr<slp::ProblemSpec> ProblemSpecFromStudy(const spec::Study& study, const spec::StudyLayout& layout) {
  slp::ProblemSpec problem;
  const int n = static_cast<int>(study.variables.size());
  problem.lower.resize(n);
  problem.upper.resize(n);
  problem.initial.resize(n);
  for (int i = 0; i < n; ++i) {
    const spec::DesignVariable& v = study.variables[static_cast<size_t>(i)];
    problem.variable_names.push_back(v.name);
    problem.lower[i] = v.lower;
    problem.upper[i] = v.upper;
    problem.initial[i] = v.initial;
  }
  switch (layout.objective_form) {
    case spec::ObjectiveForm::kScalar:
      problem.objective_form = slp::ObjectiveForm::kScalar;
      break;
    case spec::ObjectiveForm::kMinMax:
      problem.objective_form = slp::ObjectiveForm::kMinMax;
      break;
    case spec::ObjectiveForm::kSumOfMax:
      problem.objective_form = slp::ObjectiveForm::kSumOfMax;
      problem.objective_group_sizes = layout.objective_group_sizes;
      break;
  }
  problem.num_objective_terms = layout.num_objective_terms();
  const int m = layout.num_constraints();
  problem.constraint_limits.resize(m);
  problem.constraint_scales.resize(m);
  for (int h = 0; h < m; ++h) {
    const spec::ConstraintRow& row = layout.rows[static_cast<size_t>(h)];
    problem.constraint_names.push_back(row.name);
    problem.constraint_limits[h] = row.limit_si;
    problem.constraint_scales[h] = row.scale;
  }
  absl::Status valid = InStudy(study, problem.Validate());
  if (!valid.ok()) return valid;
  return problem;
}

absl::StatusOr<slp::SlpOptions> SlpOptionsFromStudy(const spec::Study& study) {
  slp::SlpOptions options;
  const spec::OptimizerSettings& s = study.optimizer;
  options.initial_move_limit = s.initial_move_limit.value_or(options.initial_move_limit);
  options.max_cycles = s.max_cycles.value_or(options.max_cycles);
  options.convergence_objective_tolerance =
      s.convergence_objective_tolerance.value_or(options.convergence_objective_tolerance);
  options.convergence_violation_tolerance =
      s.convergence_violation_tolerance.value_or(options.convergence_violation_tolerance);
  if (!s.convergence_violation_tolerance.has_value()) {
    // An equality's rows are scaled by the value's size, so that the move
    // limits see its violations in proportion (spec::EqualityRowScale), and
    // hold the middle half of its band: the violation a converged design may
    // keep is narrowed to the outer quarter on each side, or "converged"
    // could end outside a band narrower than the default tolerance.
    for (const spec::Constraint& c : study.constraints) {
      if (!c.equals.has_value() || !c.lower.has_value() || !c.upper.has_value()) continue;
      const double quarter_band_si = 0.25 * (*c.upper - *c.lower) * c.si_per_unit;
      options.convergence_violation_tolerance =
          std::min(options.convergence_violation_tolerance, quarter_band_si / spec::EqualityRowScale(c));
    }
  }
  options.convergence_optimality_tolerance =
      s.convergence_optimality_tolerance.value_or(options.convergence_optimality_tolerance);
  options.screening_threshold = s.screening_threshold.value_or(options.screening_threshold);
  options.finite_difference =
      s.central_differences ? slp::FiniteDifferenceScheme::kCentral : slp::FiniteDifferenceScheme::kForward;
  options.finite_difference_relative_step =
      s.finite_difference_relative_step.value_or(options.finite_difference_relative_step);
  options.analyses_provide_gradients = s.simulator_sensitivities;
  // The study states the target in the reported sense (a maximized value as
  // itself); the optimizer minimizes sign * value.
  if (s.objective_target.has_value()) {
    options.objective_target = study.objective.ReportedSign() * *s.objective_target;
  }
  // Without an objective F is 0 everywhere: the first accepted design that
  // meets the constraints is the answer, and nothing after it is better.
  if (study.objective.form == spec::Objective::Form::kFeasible) options.objective_target = 0.0;
  absl::Status valid = InStudy(study, options.Validate());
  if (!valid.ok()) return valid;
  return options;
}

}  // namespace mbopt::jobs
