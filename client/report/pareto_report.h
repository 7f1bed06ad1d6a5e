// The report page of a Pareto front's job (docs/report.md, "Pareto
// fronts"): the front drawn as the objective against the traded
// constraint's largest value (a front of three objectives: its three
// pairwise projections), every point labelled with its number, the
// dominated and the failed points set apart, the chosen point (if one was
// picked) marked; then the table of the points and, for the chosen one, its
// design and its constraints, its run's cycle history (the single job's
// page's history plots and cycle table) and its objective's and
// constraints' responses over time against the initial design's (the
// single job's page's plots, client/report/response_plots.h). Plain data in, one
// self-contained HTML page out.
//
// Units: the objective in `objective_unit`, the traded constraint's value
// and levels in `against_unit`, designs in their variables' units,
// constraint values normalized ((g - limit) / scale, > 0 violated).
#pragma once

#include <string>
#include <vector>

#include "client/report/report_data.h"

namespace mbopt::report {

struct ParetoReportData {
  std::string job_id;
  std::string study_name;
  std::string description;
  std::string state;
  std::string message;
  std::string objective_unit;
  bool objective_maximized = false;  // F is a value the study maximizes: each point its greatest
  std::string against;       // the traded constraint's name, or the second objective's label
  bool against_objective = false;  // the second objective is an objective, not a constraint's value
  bool against_maximized = false;  // ... a maximized one: values as themselves, a level a least value
  std::string against_unit;
  // A front of three objectives: the second traded constraint, drawn as
  // the three pairwise projections of the points (F against each traded
  // value, and the two traded values against each other).
  bool three = false;
  std::string against3;
  std::string against3_unit;
  int points_total = 0;
  std::vector<std::string> variable_names;
  std::vector<std::string> variable_units;
  std::vector<std::string> constraint_names;

  struct Point {
    int index = 0;                  // 1-based
    double level = 0;               // NaN at the two ends
    double objective = 0;           // NaN without a result
    double value = 0;               // the traded constraint's largest value
    double level3 = 0;              // a front of three objectives: the third's level and value
    double value3 = 0;
    double max_violation = 0;
    std::string run_state;          // "converged", ..., "not_run"
    int cycles = 0;
    std::string status;             // "front", "dominated", "infeasible", "failed", "not run"
    std::string reason;
    std::vector<double> design;     // physical, per variable
    std::vector<double> constraints;  // per constraint name
  };
  std::vector<Point> points;  // in the points' order
  int chosen = 0;             // 1-based; 0: none picked
  // The chosen point's responses, analysed again at its design and at the
  // study's initial one (final_label names the point); when empty,
  // `chosen_responses_note` says why.
  std::vector<ResponsePlot> chosen_responses;
  std::string chosen_responses_note;
  // The chosen point's run's cycle history, as a single job's page shows
  // its own (records, variables, objective unit; its F the run's: at the far
  // end, the second objective as minimized); when it has no records,
  // `chosen_history_note` says why.
  ReportData chosen_history;
  std::string chosen_history_note;
};

std::string RenderParetoReportHtml(const ParetoReportData& data);

}  // namespace mbopt::report
