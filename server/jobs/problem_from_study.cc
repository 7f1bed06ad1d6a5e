#include "server/jobs/problem_from_study.h"

#include "absl/strings/str_cat.h"

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
  problem.objective_form = layout.objective_form == spec::ObjectiveForm::kMinMax ? slp::ObjectiveForm::kMinMax
                                                                                 : slp::ObjectiveForm::kScalar;
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
  absl::Status valid = InStudy(study, options.Validate());
  if (!valid.ok()) return valid;
  return options;
}

}  // namespace mbopt::jobs
