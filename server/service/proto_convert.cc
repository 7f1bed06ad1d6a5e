#include "server/service/proto_convert.h"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>
#include <google/protobuf/unknown_field_set.h>

#include "absl/strings/str_cat.h"
#include "common/check.h"
#include "spec/io/analysis_outcome_convert.h"
#include "spec/io/study_io.h"

namespace mbopt::service {

v1::JobState ToProto(jobs::JobState state) { return static_cast<v1::JobState>(static_cast<int>(state)); }

v1::JobSummary ToProto(const jobs::manager::JobSummaryData& s) {
  v1::JobSummary out;
  out.set_job_id(s.job_id);
  out.set_study_name(s.study_name);
  out.set_owner(s.owner);
  out.set_waiting_for(s.waiting_for);
  out.set_state(ToProto(s.state));
  out.set_cycles(s.cycles);
  out.set_analyses(s.analyses);
  out.set_objective(s.objective);
  out.set_objective_unit(s.objective_unit);
  out.set_max_violation(s.max_violation);
  for (const std::string& name : s.design_names) out.add_design_names(name);
  for (double value : s.design) out.add_design(value);
  for (const std::string& unit : s.design_units) out.add_design_units(unit);
  out.set_wall_seconds(s.wall_seconds);
  out.set_message(s.message);
  out.set_created_unix_ms(s.created_unix_ms);
  out.set_max_cycles(s.max_cycles);
  out.set_design_set(s.design_set);
  out.set_pareto(s.pareto);
  for (const auto& [kind, count] : s.failed_analyses_by_kind) (*out.mutable_failed_analyses_by_kind())[kind] = count;
  return out;
}

jobs::manager::WorkerReport WorkerReportFromProto(const v1::TaskResult& result, const std::string& holder) {
  jobs::manager::WorkerReport report;
  report.worker_id = result.worker_id();
  report.holder = holder;
  report.task_id = result.task_id();
  report.job_id = result.job_id();
  jobs::AnalysisRecord& record = report.record;
  record.request_id = result.request_id();
  if (!result.ok()) {
    record.failure = spec::AnalysisFailure::Of(spec::io::FailureKindFromProto(result.failure_kind()),
                                               result.failure_reason());
  }
  record.objective_terms.assign(result.objective_terms().begin(), result.objective_terms().end());
  record.constraint_values.assign(result.constraint_values().begin(), result.constraint_values().end());
  record.objective_terms_packed = result.objective_terms_packed();
  record.constraint_values_packed = result.constraint_values_packed();
  record.objective_gradients.assign(result.objective_gradients().begin(), result.objective_gradients().end());
  record.constraint_gradients.assign(result.constraint_gradients().begin(), result.constraint_gradients().end());
  record.gradients_unavailable = result.gradients_unavailable();
  record.counters = spec::io::CountersFromProto(result.counters());
  return report;
}

namespace {

std::string RowName(int row, const spec::StudyLayout* layout) {
  if (row < 0) return "";
  if (layout != nullptr && static_cast<size_t>(row) < layout->rows.size()) {
    return layout->rows[static_cast<size_t>(row)].name;
  }
  return absl::StrCat("row ", row);
}

}  // namespace

v1::CycleRecord ToProto(const slp::CycleRecord& r, const spec::StudyLayout* layout,
                        const std::vector<double>& variable_scales, double objective_sign) {
  v1::CycleRecord out;
  out.set_cycle(r.cycle);
  out.set_attempt(r.attempt);
  out.set_accepted(r.accepted);
  out.set_rejection_reason(r.rejection_reason);
  for (Eigen::Index i = 0; i < r.x0.size(); ++i) out.add_x0_scaled(r.x0[i]);
  for (Eigen::Index i = 0; i < r.x_trial.size(); ++i) {
    out.add_x_trial_scaled(r.x_trial[i]);
    const double scale = static_cast<size_t>(i) < variable_scales.size() ? variable_scales[static_cast<size_t>(i)] : 1.0;
    out.add_x_trial_physical(scale * r.x_trial[i]);
  }
  out.set_objective_x0(objective_sign * r.objective_x0);
  out.set_objective_trial(objective_sign * r.objective_trial);
  out.set_objective_predicted(objective_sign * r.objective_predicted);
  out.set_max_violation_x0(r.max_violation_x0);
  out.set_max_violation_trial(r.max_violation_trial);
  out.set_worst_constraint(RowName(r.worst_constraint_trial, layout));
  out.set_objective_error(r.objective_error);
  out.set_max_approximation_error(r.max_approximation_error);
  out.set_optimality_residual(r.optimality_residual);
  out.set_worst_approximation(r.worst_approximation_row < 0 ? "objective"
                                                            : RowName(r.worst_approximation_row, layout));
  out.set_lp_feasible(r.lp_feasible);
  out.set_infeasibility(r.infeasibility);
  out.set_lp_status(r.lp_status);
  out.set_lp_iterations(r.lp_iterations);
  out.set_rows_screened_in(r.rows_screened_in);
  for (Eigen::Index i = 0; i < r.move_limits.size(); ++i) out.add_move_limits(r.move_limits[i]);
  for (Eigen::Index i = 0; i < r.move_limits_next.size(); ++i) out.add_move_limits_next(r.move_limits_next[i]);
  for (bool b : r.on_move_limit) out.add_on_move_limit(b);
  for (bool b : r.on_bound) out.add_on_bound(b);
  out.set_analyses_total(r.analyses_total);
  out.set_converged(r.converged);
  out.set_restoration(r.restoration);
  for (double v : r.constraint_violations) out.add_constraint_violations(v);
  out.set_failure_kind(r.failure_kind);
  out.set_design_set(r.design_set);
  out.set_pareto_point(r.pareto_point);
  if (r.pareto) {
    out.set_pareto(true);
    out.set_pareto_level_si(r.pareto_level_si);
    out.set_pareto_value_si(r.pareto_value_si);
    out.set_pareto_state(r.pareto_state);
    out.set_pareto_cycles(r.pareto_cycles);
    out.set_pareto_analyses(r.pareto_analyses);
    if (r.pareto_three) {
      out.set_pareto_three(true);
      out.set_pareto_level3_si(r.pareto_level3_si);
      out.set_pareto_value3_si(r.pareto_value3_si);
    }
  }
  return out;
}

v1::CycleRecord ToProto(const slp::CycleRecord& r, const jobs::manager::JobView& view) {
  v1::CycleRecord out = ToProto(r, view.layout.get(), view.variable_scales, view.ReportedFactor(r));
  if (r.pareto) {
    out.set_pareto_value(view.pareto_shown_factor * r.pareto_value_si);
    out.set_pareto_level(view.pareto_shown_factor * r.pareto_level_si);
    if (r.pareto_three) {
      out.set_pareto_value3(view.pareto_third_shown_factor * r.pareto_value3_si);
      out.set_pareto_level3(view.pareto_third_shown_factor * r.pareto_level3_si);
    }
  }
  return out;
}

void SetSerializedMessageField(int field_number, const std::string& serialized, google::protobuf::Message* out) {
  const google::protobuf::FieldDescriptor* field = out->GetDescriptor()->FindFieldByNumber(field_number);
  MBOPT_CHECK(field != nullptr && field->type() == google::protobuf::FieldDescriptor::TYPE_MESSAGE &&
                  !field->is_repeated() && !out->GetReflection()->HasField(*out, field),
              "SetSerializedMessageField: not an unset singular message field");
  out->GetReflection()->MutableUnknownFields(out)->AddLengthDelimited(field_number, serialized);
}

absl::StatusOr<spec::Study> DecodeStudy(const std::string& bytes, const std::string& source_name) {
  v1::Study study;
  if (!study.ParseFromString(bytes)) {
    return absl::InvalidArgumentError(absl::StrCat(source_name, ": the stored study is not a valid mbopt.v1.Study"));
  }
  return spec::io::StudyFromProto(study, source_name);
}

}  // namespace mbopt::service
