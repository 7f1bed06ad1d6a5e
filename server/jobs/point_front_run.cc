#include "server/jobs/point_front_run.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "common/check.h"

namespace mbopt::jobs {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The fields every point's record has, run or not.
void FillPointFields(int k, slp::CycleRecord* r) {
  r->design_set = true;
  r->pareto = true;
  r->cycle = k + 1;
}

}  // namespace

void AppendRow(const std::vector<double>& matrix, std::size_t columns, int row, double factor,
               std::vector<double>* out) {
  const std::size_t first = static_cast<std::size_t>(row) * columns;
  for (std::size_t c = 0; c < columns; ++c) out->push_back(matrix[first + c] * factor);
}

double LimitScale(double limit) { return limit != 0.0 ? std::abs(limit) : 1.0; }

absl::Status CheckTradedRowsShareLimit(const slp::ProblemSpec& p, const std::vector<int>& rows) {
  for (int h : rows) {
    if (p.constraint_limits[h] != p.constraint_limits[rows[0]] || p.constraint_scales[h] != p.constraint_scales[rows[0]]) {
      return absl::InvalidArgumentError(absl::StrCat("the traded constraint's rows \"", p.constraint_names[rows[0]],
                                                     "\" and \"", p.constraint_names[h],
                                                     "\" have different limits; a front moves one limit"));
    }
  }
  return absl::OkStatus();
}

void KeepStudyRows(const slp::ProblemSpec& study, const std::vector<int>& rows, slp::ProblemSpec* problem) {
  problem->constraint_names.assign(rows.size(), "");
  problem->constraint_limits = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(rows.size()));
  problem->constraint_scales = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(rows.size()));
  for (std::size_t j = 0; j < rows.size(); ++j) {
    const int h = rows[j];
    if (h < 0) continue;
    const auto row = static_cast<Eigen::Index>(j);
    problem->constraint_names[j] = study.constraint_names[static_cast<std::size_t>(h)];
    problem->constraint_limits[row] = study.constraint_limits[h];
    problem->constraint_scales[row] = study.constraint_scales[h];
  }
}

void MinimizeTradedRows(int terms, slp::ProblemSpec* problem, slp::SlpOptions* options) {
  problem->num_objective_terms = terms;
  problem->objective_form = terms == 1 ? slp::ObjectiveForm::kScalar : slp::ObjectiveForm::kMinMax;
  problem->objective_group_sizes.clear();
  options->objective_target.reset();  // the study's target is for its own objective
}

namespace front_detail {

absl::Status NotPending(std::int64_t request_id) {
  return absl::InvalidArgumentError(absl::StrCat("request ", request_id, " is not pending in the front"));
}

void CheckPointProblem(int k, const slp::ProblemSpec& problem) {
  const absl::Status valid = problem.Validate();
  MBOPT_CHECK(valid.ok(), absl::StrCat("Pareto point ", k + 1, ": ", valid.message()).c_str());
}

void AnalyseDesign(const slp::ProblemSpec& p, const std::vector<int>& row_constraints, int num_constraints,
                   const AnalysisRecord& record, AnalysedDesign* a) {
  a->x = Eigen::Map<const Eigen::VectorXd>(record.x_scaled.data(), static_cast<Eigen::Index>(record.x_scaled.size()));
  const Eigen::Map<const Eigen::VectorXd> terms(record.objective_terms.data(),
                                                static_cast<Eigen::Index>(record.objective_terms.size()));
  a->objective = slp::ObjectiveValue(p, terms);
  a->violations.assign(static_cast<std::size_t>(num_constraints), kNaN);
  for (std::size_t h = 0; h < record.constraint_values.size(); ++h) {
    const double g = record.constraint_values[h];
    const auto row = static_cast<Eigen::Index>(h);
    const int c = row_constraints[h];
    if (c >= 0 && c < num_constraints) {
      const double normalized = (g - p.constraint_limits[row]) / p.constraint_scales[row];
      double& of_constraint = a->violations[static_cast<std::size_t>(c)];
      of_constraint = std::isnan(of_constraint) ? normalized : std::max(of_constraint, normalized);
    }
  }
}

slp::AnalysisResult ResultHeader(const AnalysisRecord& record) {
  slp::AnalysisResult result;
  result.request_id = record.request_id;
  result.outcome = record.ok() ? slp::AnalysisOutcome::kOk : slp::AnalysisOutcome::kFailed;
  result.failure_reason = record.failure.reason;
  return result;
}

void FillNotRunRecord(int k, const Eigen::VectorXd& initial, const std::string& reason, int num_constraints,
                      slp::CycleRecord* r) {
  FillPointFields(k, r);
  r->x0 = r->x_trial = initial;
  r->accepted = false;
  r->rejection_reason = reason;
  r->objective_x0 = r->objective_trial = r->objective_predicted = kNaN;
  r->max_violation_x0 = r->max_violation_trial = kNaN;
  r->objective_error = r->max_approximation_error = r->optimality_residual = kNaN;
  r->constraint_violations.assign(static_cast<std::size_t>(num_constraints), kNaN);
  r->pareto_state = "not_run";
}

bool FillEndedRecord(int k, const slp::SlpOptimizer& run, const slp::DesignPoint& best, const AnalysedDesign* values,
                     double violation_tolerance, int num_constraints, slp::CycleRecord* r) {
  FillPointFields(k, r);
  r->x0 = r->x_trial = best.x;
  r->objective_predicted = r->objective_error = r->max_approximation_error = r->optimality_residual = kNaN;
  r->pareto_state = slp::RunStateName(run.state());
  r->pareto_cycles = run.cycles_completed();
  r->pareto_analyses = run.analyses_used();
  if (values == nullptr) {
    r->objective_x0 = r->objective_trial = kNaN;
    r->max_violation_x0 = r->max_violation_trial = kNaN;
    r->constraint_violations.assign(static_cast<std::size_t>(num_constraints), kNaN);
  } else {
    r->objective_x0 = r->objective_trial = values->objective;
    r->max_violation_x0 = r->max_violation_trial = best.max_violation;
    r->constraint_violations = values->violations;
  }
  const bool usable =
      values != nullptr && run.state() != slp::RunState::kFailed && best.max_violation <= violation_tolerance;
  r->accepted = usable;
  if (!usable) {
    // A point whose bounds no design meets (a level beyond the front's
    // reach) ends here too: its best design still violates.
    r->rejection_reason = run.state() == slp::RunState::kFailed || values == nullptr
                              ? absl::StrCat("the run failed: ", run.end_reason())
                              : absl::StrFormat("no feasible design: maxg %.4g at the best design", best.max_violation);
  }
  return usable;
}

bool SameBits(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && (a.size() == 0 || std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0);
}

}  // namespace front_detail
}  // namespace mbopt::jobs
