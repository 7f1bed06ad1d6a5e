// The report page of a design set's job (a sweep or sample, docs/study.md):
// the objective and each constraint against the swept variable (a grid: one
// curve per value of its second variable; a sample: the objective against
// each variable, as points), with the constraints' limit drawn, and the
// table of every design. Plain data in, one self-contained HTML page out.
//
// Units: designs are physical values in their variable's unit; objective
// values in `objective_unit`; constraint values normalized, (g - limit) /
// scale, dimensionless, > 0 violated. A constraint whose rows share one
// limit and scale is plotted in its own unit with its limit there
// (ConstraintInUnit); the table keeps the normalized values.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace mbopt::report {

struct DesignSetReportData {
  std::string job_id;
  std::string study_name;
  std::string description;
  std::string state;    // e.g. "completed", "running"
  std::string message;
  std::string objective_unit;
  std::int64_t designs_total = 0;
  std::vector<std::string> variable_names;
  std::vector<std::string> variable_units;
  // The swept variables' indices: one (a line) or two (a grid; the curves
  // are the second one's values). Empty: a sample.
  std::vector<int> swept;
  std::vector<std::string> constraint_names;

  // How a constraint's normalized value n reads in its unit: value = limit
  // + per_normalized * n. per_normalized < 0 for a lower limit (the value
  // is then the constraint's least, violated below the limit); otherwise
  // the value is its largest (of |value| for a MAX_ABS constraint, whose
  // `quantity` is then "|name|"), violated above.
  struct ConstraintInUnit {
    bool known = false;  // false: plotted normalized, the limit at 0
    std::string quantity;
    std::string unit;
    double limit = 0;
    double per_normalized = 1;
  };
  std::vector<ConstraintInUnit> constraints_in_unit;  // per constraint name, or empty

  struct Design {
    int index = 0;                         // 1-based
    std::vector<double> values;            // physical, per variable
    double objective = 0;                  // NaN when the analysis failed
    double max_violation = 0;
    std::vector<double> constraints;       // per constraint name
    std::string status;                    // "ok" or the failure kind
    std::string failure_reason;
  };
  std::vector<Design> designs;  // in the designs' order
};

std::string RenderDesignSetReportHtml(const DesignSetReportData& data);

}  // namespace mbopt::report
