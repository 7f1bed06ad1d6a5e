#include "client/pareto_report_from_job.h"

#include <string>
#include <utility>

#include "client/job_format.h"
#include "client/pareto_format.h"
#include "client/report_responses.h"

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
  data.against_objective = front.against_objective;
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

void AddChosenPointResponses(const v1::GetJobResponse& job, report::ParetoReportData* data) {
  const std::string name = "point " + std::to_string(data->chosen);
  const v1::CycleRecord* record = nullptr;
  for (const v1::CycleRecord& r : job.cycles()) {
    if (r.pareto() && r.cycle() == data->chosen) record = &r;
  }
  if (record == nullptr || record->pareto_state() == "not_run" ||
      record->x_trial_physical_size() != job.summary().design_size()) {
    data->chosen_responses_note = "The responses are not shown: " + name + " has no design of its own.";
    return;
  }
  // The point's design stands in for a single job's final design.
  v1::GetJobResponse as_single = job;
  as_single.mutable_summary()->mutable_design()->Assign(record->x_trial_physical().begin(),
                                                         record->x_trial_physical().end());
  report::ReportData single;
  if (absl::Status added = AddResponsePlots(as_single, {}, &single); !added.ok()) {
    data->chosen_responses_note = "The responses are not shown: " + std::string(added.message());
    return;
  }
  for (report::ResponsePlot& plot : single.responses) {
    plot.final_label = name;
    data->chosen_responses.push_back(std::move(plot));
  }
  data->chosen_responses_note = single.responses_note;
}

}  // namespace mbopt::client
