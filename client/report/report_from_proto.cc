#include "client/report/report_from_proto.h"

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

namespace mbopt::report {

std::string JobStateName(v1::JobState state) {
  switch (state) {
    case v1::JOB_STATE_QUEUED: return "queued";
    case v1::JOB_STATE_RUNNING: return "running";
    case v1::JOB_STATE_CONVERGED: return "converged";
    case v1::JOB_STATE_MAX_CYCLES: return "max_cycles";
    case v1::JOB_STATE_STALLED: return "stalled";
    case v1::JOB_STATE_FAILED: return "failed";
    case v1::JOB_STATE_CANCELLED: return "cancelled";
    case v1::JOB_STATE_INTERRUPTED: return "interrupted";
    case v1::JOB_STATE_COMPLETED: return "completed";
    default: return "unknown";
  }
}

namespace {

template <typename T>
std::vector<T> ToVector(const google::protobuf::RepeatedField<T>& values) {
  return std::vector<T>(values.begin(), values.end());
}

ReportCycle FromProto(const v1::CycleRecord& r) {
  ReportCycle c;
  c.cycle = r.cycle();
  c.attempt = r.attempt();
  c.accepted = r.accepted();
  c.rejection_reason = r.rejection_reason();
  c.x0_scaled = ToVector(r.x0_scaled());
  c.x_trial_scaled = ToVector(r.x_trial_scaled());
  c.objective_x0 = r.objective_x0();
  c.objective_trial = r.objective_trial();
  c.objective_predicted = r.objective_predicted();
  c.max_violation_x0 = r.max_violation_x0();
  c.max_violation_trial = r.max_violation_trial();
  c.worst_constraint = r.worst_constraint();
  c.objective_error = r.objective_error();
  c.max_approximation_error = r.max_approximation_error();
  c.optimality_residual = r.optimality_residual();
  c.worst_approximation = r.worst_approximation();
  c.lp_feasible = r.lp_feasible();
  c.infeasibility = r.infeasibility();
  c.lp_status = r.lp_status();
  c.move_limits = ToVector(r.move_limits());
  c.move_limits_next = ToVector(r.move_limits_next());
  c.analyses_total = r.analyses_total();
  c.converged = r.converged();
  return c;
}

}  // namespace

ReportData ReportDataFromJob(const v1::GetJobResponse& job) {
  const v1::JobSummary& s = job.summary();
  ReportData d;
  d.job_id = s.job_id();
  d.study_name = !s.study_name().empty() ? s.study_name() : job.study().name();
  d.description = job.study().description();
  d.state = JobStateName(s.state());
  d.message = s.message();
  d.cycles = s.cycles();
  d.analyses = s.analyses();
  // The server leaves objective and violation at 0 until x0 of cycle 1 has
  // been analysed, which shows as a first record.
  d.objective = job.cycles_size() > 0 ? s.objective() : std::numeric_limits<double>::quiet_NaN();
  d.objective_unit = !s.objective_unit().empty() ? s.objective_unit() : job.study().objective().unit();
  d.max_violation = job.cycles_size() > 0 ? s.max_violation() : std::numeric_limits<double>::quiet_NaN();
  d.wall_seconds = s.wall_seconds();
  d.failed_analyses_by_kind.insert(s.failed_analyses_by_kind().begin(), s.failed_analyses_by_kind().end());

  const auto& study_variables = job.study().variables();
  const int n = std::max(s.design_names_size(), study_variables.size());
  for (int i = 0; i < n; ++i) {
    ReportVariable v;
    if (i < study_variables.size()) {
      const v1::DesignVariable& sv = study_variables.Get(i);
      v.name = sv.name();
      v.scale = sv.scale() != 0.0 ? sv.scale() : 1.0;  // 0 means 1 (study.proto)
      v.has_bounds = true;
      v.lower_scaled = sv.lower();
      v.upper_scaled = sv.upper();
    }
    if (i < s.design_names_size() && !s.design_names(i).empty()) v.name = s.design_names(i);
    if (i < s.design_units_size()) v.unit = s.design_units(i);
    d.variables.push_back(std::move(v));
  }
  // A summary design of the wrong length cannot be matched to the names.
  if (s.design_size() == n) d.final_design_physical = ToVector(s.design());

  d.records.reserve(static_cast<std::size_t>(job.cycles_size()));
  for (const v1::CycleRecord& r : job.cycles()) d.records.push_back(FromProto(r));
  return d;
}

}  // namespace mbopt::report
