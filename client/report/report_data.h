// What the job report page shows, as plain data: the job's summary, its
// design variables with bounds, and every CycleRecord (rejected attempts
// included). Filled from the wire messages by report_from_proto.h, or by
// hand in tests; the page generator (job_report_html.h) sees only this.
//
// Units: objective values are in `objective_unit`; constraint values and
// approximation errors are normalized and dimensionless (> 0 violated);
// scaled design values are the optimizer's dimensionless variables x, with
// physical value = scale * x in the variable's `unit`.
#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "client/report/mechanism_drawing.h"

namespace mbopt::report {

// The SLP's default convergence tolerance on maxg (slp::SlpOptions'
// convergence_violation_tolerance; a test keeps the two equal).
inline constexpr double kDefaultViolationTolerance = 0.005;

struct ReportVariable {
  std::string name;
  std::string unit;        // unit of the physical value; empty: SI / none
  double scale = 1.0;      // physical value = scale * scaled value
  bool has_bounds = false; // false when the study was not available
  double lower_scaled = 0.0;
  double upper_scaled = 0.0;
};

// One LP solve of a cycle and what became of its trial point (mirrors the
// SLP core's CycleRecord). NaN marks a value that does not exist, e.g. F(x*)
// of a trial whose analysis failed.
struct ReportCycle {
  int cycle = 0;    // 1-based
  int attempt = 0;  // 0-based trial index within the cycle
  bool accepted = false;
  std::string rejection_reason;  // empty when accepted
  std::vector<double> x0_scaled;
  std::vector<double> x_trial_scaled;
  double objective_x0 = 0.0;
  double objective_trial = 0.0;
  double objective_predicted = 0.0;
  double max_violation_x0 = 0.0;
  double max_violation_trial = 0.0;
  std::string worst_constraint;  // row name of maxg at x*, empty if none
  double objective_error = 0.0;           // e_o
  double max_approximation_error = 0.0;   // maxfout
  double optimality_residual = 0.0;       // KKT residual of the LP solution
  std::string worst_approximation;        // "objective" or a row name
  bool lp_feasible = true;
  double infeasibility = 0.0;
  std::string lp_status;
  std::vector<double> move_limits;        // f_i used for this LP
  std::vector<double> move_limits_next;   // f_i after the strategy
  std::int64_t analyses_total = 0;
  bool converged = false;
};

// A constraint row with its normalized value at the final design (> 0
// violated); the page lists those above kActiveThreshold.
struct ActiveConstraint {
  std::string name;
  double normalized_value = 0.0;
};

// Axis choice for a history plot.
enum class ScaleChoice {
  kAuto,    // logarithmic when the positive values span two decades or more
  kLinear,
  kLog,
};

// A response over time at the initial and at the final design, with the
// limits a constraint puts on it: what the page's "Responses" section plots.
// Values are in `unit`. A scalar (mass, a response of parameters: one value
// per analysis, times_s of size 1 or empty) is shown as two bars.
struct ResponsePlot {
  std::string title;        // e.g. "s1: max_abs <= 0.456 in"
  std::string unit;         // empty: SI
  std::string note;         // e.g. the reduced values, or the window
  std::vector<double> times_s;
  std::vector<double> initial;  // same length as times_s
  std::vector<double> final;
  // A limit holds over the instants from_s <= t <= to_s only (a window, or
  // one instant when from_s == to_s, e.g. a FINAL bound); it is drawn there
  // and nowhere else.
  struct Limit {
    double value = 0.0;
    std::string label;
    double from_s = -std::numeric_limits<double>::infinity();
    double to_s = std::numeric_limits<double>::infinity();
  };
  std::vector<Limit> limits;
  // What `final` is the analysis of: a Pareto front's page plots a point's
  // design against the initial one.
  std::string final_label = "final design";
  bool scalar() const { return times_s.size() <= 1; }
};

// One output or response against another (the study's `plots`, or
// `mbopt report --plot X:Y`), at the initial and the final design, each
// axis in its signal's unit. A curve is the pairs (x(t_i), y(t_i)) over the
// time grid.
struct XyPlot {
  std::string title;
  std::string x_label;  // e.g. "crank_angle [deg]"
  std::string y_label;
  std::vector<double> initial_x, initial_y;  // same lengths
  std::vector<double> final_x, final_y;
};

struct ReportData {
  std::string job_id;
  std::string study_name;
  std::string description;
  std::string state;       // e.g. "converged", "max_cycles", "running"
  std::string message;     // failure or stall reason
  int cycles = 0;          // cycles completed
  std::int64_t analyses = 0;
  double objective = 0.0;  // current best F, NaN when unknown
  std::string objective_unit;
  double max_violation = 0.0;  // normalized maxg of the current best design
  double wall_seconds = 0.0;
  // Failed analyses by failure kind name ("integrator", "assembly", ...).
  std::map<std::string, std::int64_t> failed_analyses_by_kind;

  std::vector<ReportVariable> variables;
  // Current best design in physical units, one per variable; empty when
  // unknown (the page then derives it from the last accepted record).
  std::vector<double> final_design_physical;
  // Rows known to be active at the final design beyond its worst row as the
  // job record has it (the record keeps only that one per trial point).
  std::vector<ActiveConstraint> active_constraints;
  // True when `active_constraints` holds every row of an analysis of the
  // final design (at least its worst row, active or not): the page then
  // lists the active rows from it rather than from the cycle records.
  bool active_constraints_complete = false;
  // maxg below this counts as met for convergence (the SLP's
  // convergence_violation_tolerance for this job's study): a value in
  // (0, violation_tolerance] is within the tolerance, not "violated".
  double violation_tolerance = kDefaultViolationTolerance;

  std::vector<ReportCycle> records;  // in the order the optimizer emitted them
  // The responses at the initial and final designs; when there are none,
  // `responses_note` says why (e.g. the analyses could not be run).
  std::vector<ResponsePlot> responses;
  std::string responses_note;
  // The scene drawn at the initial and final designs.
  MechanismDrawings mechanism;
  // The x-y plots asked for, from the same two analyses.
  std::vector<XyPlot> xy_plots;

  // kAuto for the objective: logarithmic only when every value is > 0.
  ScaleChoice objective_scale = ScaleChoice::kAuto;
  ScaleChoice error_scale = ScaleChoice::kAuto;
  ScaleChoice violation_scale = ScaleChoice::kAuto;
  ScaleChoice move_limit_scale = ScaleChoice::kAuto;
};

// Rows with a normalized value above this count as active (METHOD.md's
// convergence tolerance on maxg).
inline constexpr double kActiveThreshold = -0.005;

}  // namespace mbopt::report
