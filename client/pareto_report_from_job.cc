#include "client/pareto_report_from_job.h"

#include "client/job_format.h"
#include "client/pareto_format.h"

namespace mbopt::client {

report::ParetoReportData ParetoReportFromJob(const v1::GetJobResponse& job, int chosen) {
  const v1::JobSummary& s = job.summary();
  const ParetoFront front = FrontOfJob(job);
  report::ParetoReportData data;
  data.job_id = s.job_id();
  data.study_name = s.study_name();
  data.description = job.study().description();
  data.state = StateName(s.state());
  data.message = s.message();
  data.objective_unit = s.objective_unit();
  data.against = front.against;
  data.against_unit = front.unit;
  data.points_total = s.max_cycles();
  data.variable_names.assign(s.design_names().begin(), s.design_names().end());
  data.variable_units.assign(s.design_units().begin(), s.design_units().end());
  data.variable_units.resize(data.variable_names.size());
  for (const auto& c : job.study().constraints()) data.constraint_names.push_back(c.name());
  data.chosen = chosen;
  for (const ParetoPointRow& row : front.points) {
    const v1::CycleRecord& r = *row.record;
    report::ParetoReportData::Point p;
    p.index = row.point;
    p.level = row.level;
    p.objective = row.objective;
    p.value = row.value;
    p.max_violation = r.max_violation_trial();
    p.run_state = r.pareto_state();
    p.cycles = r.pareto_cycles();
    p.status = row.status;
    p.reason = r.rejection_reason();
    p.design.assign(r.x_trial_physical().begin(), r.x_trial_physical().end());
    p.constraints.assign(r.constraint_violations().begin(), r.constraint_violations().end());
    data.points.push_back(std::move(p));
  }
  return data;
}

}  // namespace mbopt::client
