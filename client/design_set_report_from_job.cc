#include "client/design_set_report_from_job.h"

#include <cmath>
#include <string>

#include "client/report/report_from_proto.h"
#include "spec/io/study_io.h"

namespace mbopt::client {

std::vector<report::DesignSetReportData::ConstraintInUnit> ConstraintsInUnit(const spec::Study& study,
                                                                            const spec::StudyLayout& layout) {
  std::vector<report::DesignSetReportData::ConstraintInUnit> out(study.constraints.size());
  for (size_t c = 0; c < study.constraints.size(); ++c) {
    const spec::Constraint& constraint = study.constraints[c];
    const spec::ConstraintRow* first = nullptr;
    bool shared = true, upper = false, lower = false;
    for (const spec::ConstraintRow& row : layout.rows) {
      if (row.constraint != static_cast<int>(c)) continue;
      if (first == nullptr) first = &row;
      shared = shared && row.limit_si == first->limit_si && row.scale == first->scale;
      (row.value.sign < 0 ? lower : upper) = true;
    }
    // An equality's rows hold the middle half of its band (spec/layout.cc):
    // their limit is not the one written, so it stays normalized.
    if (first == nullptr || !shared || constraint.equals.has_value() || constraint.si_per_unit <= 0) continue;
    // Rows g = sign * f <= c: the largest (g - c) / s over them is n, so the
    // largest f is c + s n when every row bounds from above, the least f is
    // -(c + s n) when every row bounds from below, and rows of both signs
    // with one c bound |f| (MAX_ABS, or a band around 0).
    const double sign = upper ? 1.0 : -1.0;
    report::DesignSetReportData::ConstraintInUnit& in_unit = out[c];
    in_unit.known = true;
    in_unit.quantity = upper && lower ? "|" + constraint.name + "|" : constraint.name;
    in_unit.unit = constraint.unit;
    in_unit.limit = sign * first->limit_si / constraint.si_per_unit;
    in_unit.per_normalized = sign * first->scale / constraint.si_per_unit;
  }
  return out;
}

report::DesignSetReportData DesignSetReportFromJob(const v1::GetJobResponse& job) {
  const v1::JobSummary& s = job.summary();
  const v1::Study& study = job.study();
  report::DesignSetReportData data;
  data.job_id = s.job_id();
  data.study_name = s.study_name();
  data.description = study.description();
  data.state = report::JobStateName(s.state());
  data.message = s.message();
  data.objective_unit = s.objective_unit();
  data.designs_total = s.max_cycles();
  for (int i = 0; i < s.design_names_size(); ++i) {
    data.variable_names.push_back(s.design_names(i));
    data.variable_units.push_back(i < s.design_units_size() ? s.design_units(i) : "");
  }
  for (const v1::SweepAxis& axis : study.sweep().axis()) {
    for (size_t v = 0; v < data.variable_names.size(); ++v) {
      if (data.variable_names[v] == axis.variable()) data.swept.push_back(static_cast<int>(v));
    }
  }
  for (const v1::Constraint& c : study.constraints()) data.constraint_names.push_back(c.name());
  // The limits in the constraints' units need the study's rows; a study
  // that cannot be laid out here is plotted normalized, as before.
  if (absl::StatusOr<spec::Study> loaded = spec::io::StudyFromProto(study, "the job's study"); loaded.ok()) {
    if (absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(*loaded); layout.ok()) {
      data.constraints_in_unit = ConstraintsInUnit(*loaded, *layout);
    }
  }
  for (const v1::CycleRecord& r : job.cycles()) {
    report::DesignSetReportData::Design d;
    d.index = r.cycle();
    d.values.assign(r.x_trial_physical().begin(), r.x_trial_physical().end());
    d.objective = r.objective_trial();
    d.max_violation = r.max_violation_trial();
    d.constraints.assign(r.constraint_violations().begin(), r.constraint_violations().end());
    d.status = r.failure_kind().empty() ? "ok" : r.failure_kind();
    d.failure_reason = r.rejection_reason();
    data.designs.push_back(std::move(d));
  }
  return data;
}

}  // namespace mbopt::client
