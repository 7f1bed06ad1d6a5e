#include "client/pareto_report_from_job.h"

#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "client/job_format.h"
#include "client/pareto_format.h"
#include "client/report/report_from_proto.h"
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
  data.objective_maximized = !job.study().objective().maximize().empty();
  data.against = front.against;
  data.against_unit = front.unit;
  data.against_objective = front.against_objective;
  data.against_maximized = front.against_maximized;
  data.three = front.three;
  data.against3 = front.against3;
  data.against3_unit = front.unit3;
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
    p.level3 = row.level3;
    p.value3 = row.value3;
    p.max_violation = r.max_violation_trial();
    p.run_state = r.pareto_state();
    p.cycles = r.pareto_cycles();
    p.status = row.status;
    p.reason = r.rejection_reason();
    p.design.assign(r.x_trial_physical().begin(), r.x_trial_physical().end());
    p.constraints.assign(r.constraint_violations().begin(), r.constraint_violations().end());
    data.points.push_back(std::move(p));
  }
  if (chosen > 0) AddChosenPointHistory(job, &data);
  return data;
}

void AddChosenPointHistory(const v1::GetJobResponse& job, report::ParetoReportData* data) {
  const std::vector<const v1::CycleRecord*> cycles = PointRunCycles(job, data->chosen);
  const v1::CycleRecord* record = nullptr;
  for (const v1::CycleRecord& r : job.cycles()) {
    if (r.pareto() && r.cycle() == data->chosen) record = &r;
  }
  if (cycles.empty()) {
    data->chosen_history_note =
        record != nullptr && record->pareto_state() == "not_run"
            ? "Its run has no cycles: the point was not run."
            : "Its run's cycles are not in the job's log (a front logged before they were, or a point not "
              "ended yet).";
    return;
  }
  // The run as a single job: its records, and its result as the final design.
  v1::GetJobResponse run;
  *run.mutable_study() = job.study();
  v1::JobSummary& s = *run.mutable_summary();
  s = job.summary();
  s.set_pareto(false);
  s.set_design_set(false);
  if (record != nullptr) {
    s.set_cycles(record->pareto_cycles());
    s.set_analyses(record->pareto_analyses());
    s.set_objective(record->objective_trial());
    s.set_max_violation(record->max_violation_trial());
    s.mutable_design()->Assign(record->x_trial_physical().begin(), record->x_trial_physical().end());
  }
  for (const v1::CycleRecord* c : cycles) *run.add_cycles() = *c;
  data->chosen_history = report::ReportDataFromJob(run);
  if (IsFarEnd(job.study(), data->chosen)) {
    // Its run optimizes the second (or third) objective, whose values the
    // server reports in that objective's unit.
    const bool third = IsFrontOfThree(job.study()) && data->chosen == 3;
    data->chosen_history.objective_unit = third ? data->against3_unit : data->against_unit;
    data->chosen_history.objective = std::numeric_limits<double>::quiet_NaN();
    const std::string name = third ? data->against3 : data->against;
    data->chosen_history_note =
        IsFrontOfThree(job.study())
            ? absl::StrCat("This is the anchor of the ", third ? "third" : "second", " objective: its run's F is ", name,
                           ", which the run optimizes, not the study's objective.")
            : absl::StrCat("This is the front's far end: its run's F is ", data->against_objective ? "" : "the largest value of ",
                           name, ", which the run optimizes, not the study's objective.");
  }
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
