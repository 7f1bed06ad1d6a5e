#include "server/jobs/design_set_run.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "spec/analysis_outcome.h"

namespace mbopt::jobs {

DesignSetRun::DesignSetRun(slp::ProblemSpec problem, std::vector<Eigen::VectorXd> designs,
                           std::vector<int> row_constraints, int num_constraints)
    : problem_(std::move(problem)),
      designs_(std::move(designs)),
      row_constraints_(std::move(row_constraints)),
      num_constraints_(num_constraints),
      answered_flags_(designs_.size(), false) {}

std::vector<slp::AnalysisRequest> DesignSetRun::PendingRequests() const {
  std::vector<slp::AnalysisRequest> pending;
  for (std::size_t i = 0; i < designs_.size(); ++i) {
    if (answered_flags_[i]) continue;
    slp::AnalysisRequest request;
    request.id = static_cast<std::int64_t>(i);
    request.cycle = static_cast<int>(i) + 1;
    request.purpose = slp::RequestPurpose::kCycleStart;
    request.x = designs_[i];
    pending.push_back(std::move(request));
  }
  return pending;
}

bool DesignSetRun::IsPending(std::int64_t request_id) const {
  return request_id >= 0 && static_cast<std::size_t>(request_id) < designs_.size() &&
         !answered_flags_[static_cast<std::size_t>(request_id)];
}

absl::Status DesignSetRun::Submit(const AnalysisRecord& record) {
  if (!IsPending(record.request_id)) {
    return absl::InvalidArgumentError(absl::StrCat("design ", record.request_id, " is not pending"));
  }
  const auto index = static_cast<std::size_t>(record.request_id);
  answered_flags_[index] = true;
  ++answered_;
  waiting_.emplace(index, record);
  while (!waiting_.empty() && waiting_.begin()->first == emitted_) {
    new_records_.push_back(RecordOf(emitted_, waiting_.begin()->second));
    waiting_.erase(waiting_.begin());
    ++emitted_;
  }
  return absl::OkStatus();
}

std::vector<slp::CycleRecord> DesignSetRun::TakeNewRecords() { return std::exchange(new_records_, {}); }

slp::CycleRecord DesignSetRun::RecordOf(std::size_t index, const AnalysisRecord& record) const {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  slp::CycleRecord r;
  r.design_set = true;
  r.cycle = static_cast<int>(index) + 1;
  r.x0 = designs_[index];
  r.x_trial = designs_[index];
  r.accepted = record.ok();
  r.analyses_total = static_cast<std::int64_t>(index) + 1;
  r.constraint_violations.assign(static_cast<std::size_t>(num_constraints_), kNaN);
  // Nothing was solved: the optimizer's fields say so rather than hold zeros.
  r.objective_predicted = kNaN;
  r.objective_error = kNaN;
  r.max_approximation_error = kNaN;
  r.optimality_residual = kNaN;
  if (!record.ok()) {
    r.failure_kind = spec::FailureKindName(record.failure.kind);
    r.rejection_reason = record.failure.reason;
    r.objective_x0 = r.objective_trial = kNaN;
    r.max_violation_x0 = r.max_violation_trial = kNaN;
    return r;
  }
  const Eigen::Map<const Eigen::VectorXd> terms(record.objective_terms.data(),
                                                static_cast<Eigen::Index>(record.objective_terms.size()));
  r.objective_x0 = r.objective_trial = slp::ObjectiveValue(problem_, terms);
  double max_violation = 0;  // no rows: nothing is violated
  int worst = -1;
  for (std::size_t h = 0; h < record.constraint_values.size(); ++h) {
    const auto row = static_cast<Eigen::Index>(h);
    const double g = (record.constraint_values[h] - problem_.constraint_limits[row]) / problem_.constraint_scales[row];
    if (worst < 0 || g > max_violation) {
      max_violation = g;
      worst = static_cast<int>(h);
    }
    const int c = row_constraints_[h];
    if (c >= 0 && c < num_constraints_) {
      double& of_constraint = r.constraint_violations[static_cast<std::size_t>(c)];
      of_constraint = std::isnan(of_constraint) ? g : std::max(of_constraint, g);
    }
  }
  r.max_violation_x0 = r.max_violation_trial = max_violation;
  r.worst_constraint_trial = worst;
  return r;
}

}  // namespace mbopt::jobs
