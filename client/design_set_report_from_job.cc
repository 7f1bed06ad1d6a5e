#include "client/design_set_report_from_job.h"

#include <cmath>
#include <string>

#include "client/report/report_from_proto.h"

namespace mbopt::client {

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
