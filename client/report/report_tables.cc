#include "client/report/report_tables.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "client/report/history_plots.h"
#include "client/report/html_escape.h"
#include "client/report/number_format.h"

namespace mbopt::report {
namespace {

const ReportCycle* LastAccepted(const ReportData& data) {
  for (auto it = data.records.rbegin(); it != data.records.rend(); ++it) {
    if (it->accepted) return &*it;
  }
  return nullptr;
}

double ScaleOf(const ReportData& data, std::size_t i) {
  if (i < data.variables.size() && data.variables[i].scale != 0.0) return data.variables[i].scale;
  return 1.0;
}

std::string Cell(const std::string& text, const char* cls = nullptr) {
  if (cls == nullptr) return "<td>" + text + "</td>";
  return std::string("<td class=\"") + cls + "\">" + text + "</td>";
}

std::string Num(double v, int significant = 6) {
  return Cell(EscapeHtml(FormatValue(v, significant)), "num");
}

// A row name escaped, with a break opportunity after its '@' so that
// "<constraint>@t=<time> <side>" wraps between its parts before anywhere
// else in a narrow column.
std::string BreakableName(const std::string& name) {
  std::string escaped = EscapeHtml(name);
  const std::size_t at = escaped.find('@');
  if (at != std::string::npos) escaped.insert(at + 1, "<wbr>");
  return escaped;
}

}  // namespace

BoundFlag DesignBoundFlag(const ReportVariable& variable, double physical_value) {
  if (!variable.has_bounds || variable.scale == 0.0 || !std::isfinite(physical_value)) {
    return BoundFlag::kUnknown;
  }
  const double x = physical_value / variable.scale;
  const double lower = std::min(variable.lower_scaled, variable.upper_scaled);
  const double upper = std::max(variable.lower_scaled, variable.upper_scaled);
  const double range = upper - lower;
  const double reference = range > 0 ? range : std::max(std::abs(lower), 1.0);
  const double tol = kBoundRelativeTolerance * reference;
  if (x <= lower + tol) return BoundFlag::kAtLower;
  if (x >= upper - tol) return BoundFlag::kAtUpper;
  return BoundFlag::kNone;
}

std::vector<double> FinalDesignPhysical(const ReportData& data) {
  const std::size_t n = data.variables.size();
  if (!data.final_design_physical.empty() && (n == 0 || data.final_design_physical.size() == n)) {
    return data.final_design_physical;
  }
  const std::vector<double>* scaled = nullptr;
  if (const ReportCycle* r = LastAccepted(data); r != nullptr) {
    scaled = &r->x_trial_scaled;
  } else if (!data.records.empty()) {
    scaled = &data.records.front().x0_scaled;
  }
  std::vector<double> out;
  if (scaled == nullptr) return out;
  for (std::size_t i = 0; i < scaled->size(); ++i) out.push_back(ScaleOf(data, i) * (*scaled)[i]);
  return out;
}

std::string FinalDesignTableHtml(const ReportData& data) {
  const std::vector<double> design = FinalDesignPhysical(data);
  const std::size_t n = std::max(design.size(), data.variables.size());
  if (n == 0) return "<p class=\"empty\">No design variables are known for this job.</p>\n";
  std::string out;
  if (!data.records.empty() && LastAccepted(data) == nullptr) {
    out += "<p class=\"note\">No trial point has been accepted: this is the initial design.</p>\n";
  }
  out +=
      "<table class=\"design\">\n<thead><tr><th>variable</th><th>value</th><th>unit</th>"
      "<th>lower bound</th><th>upper bound</th><th>bound</th></tr></thead>\n<tbody>\n";
  for (std::size_t i = 0; i < n; ++i) {
    const double value = i < design.size() ? design[i] : std::nan("");
    const bool known = i < data.variables.size();
    const ReportVariable variable = known ? data.variables[i] : ReportVariable{};
    std::string lower = "\u2014", upper = "\u2014";
    if (variable.has_bounds) {
      const double a = variable.scale * variable.lower_scaled;
      const double b = variable.scale * variable.upper_scaled;
      lower = FormatValue(std::min(a, b));
      upper = FormatValue(std::max(a, b));
    }
    const BoundFlag flag = DesignBoundFlag(variable, value);
    std::string flag_text;
    const char* flag_class = "flag";
    switch (flag) {
      case BoundFlag::kAtLower: flag_text = "at lower bound"; flag_class = "flag on-bound"; break;
      case BoundFlag::kAtUpper: flag_text = "at upper bound"; flag_class = "flag on-bound"; break;
      case BoundFlag::kNone: flag_text = ""; break;
      case BoundFlag::kUnknown: flag_text = variable.has_bounds ? "\u2014" : "bounds unknown"; break;
    }
    out += "<tr>" + Cell(EscapeHtml(VariableName(data, static_cast<int>(i)))) + Num(value) +
           Cell(EscapeHtml(variable.unit)) + Cell(EscapeHtml(lower), "num") +
           Cell(EscapeHtml(upper), "num") + Cell(EscapeHtml(flag_text), flag_class) + "</tr>\n";
  }
  out += "</tbody>\n</table>\n";
  return out;
}

const ReportCycle* RecordOfFinalDesign(const ReportData& data) {
  const std::vector<double> design = FinalDesignPhysical(data);
  if (design.empty()) return nullptr;
  auto same = [&](const ReportCycle& r) {
    if (r.x_trial_scaled.size() != design.size()) return false;
    for (std::size_t i = 0; i < design.size(); ++i) {
      const double v = ScaleOf(data, i) * r.x_trial_scaled[i];
      if (!(std::abs(v - design[i]) <= kSameDesignRelativeTolerance * std::max(std::abs(design[i]), std::abs(v)))) {
        return false;
      }
    }
    return std::isfinite(r.max_violation_trial);
  };
  const ReportCycle* last = nullptr;
  for (auto it = data.records.rbegin(); it != data.records.rend(); ++it) {
    if (!same(*it)) continue;
    if (last == nullptr) last = &*it;
    if (it->max_violation_trial == data.max_violation) return &*it;
  }
  return last;
}

std::string ViolationMark(const ReportData& data, double normalized_value) {
  if (!(normalized_value > 0)) return "";
  if (normalized_value > data.violation_tolerance) return " (violated)";
  return " (within the tolerance " + FormatValue(data.violation_tolerance, 4) + ")";
}

std::string ActiveConstraintsHtml(const ReportData& data) {
  struct Row {
    std::string name;
    double value;
    std::string source;
  };
  std::vector<Row> rows;
  auto table = [&]() {
    std::string out =
        "<table class=\"active\">\n<thead><tr><th>constraint row</th><th>normalized value</th>"
        "<th>status</th><th>source</th></tr></thead>\n<tbody>\n";
    for (const Row& r : rows) {
      const std::string mark = ViolationMark(data, r.value);
      // The mark's words without its parentheses; a met row is just active.
      const std::string status = mark.empty() ? "active" : mark.substr(2, mark.size() - 3);
      out += "<tr>" + Cell(EscapeHtml(r.name)) + Num(r.value) + Cell(EscapeHtml(status)) +
             Cell(EscapeHtml(r.source)) + "</tr>\n";
    }
    return out + "</tbody>\n</table>\n";
  };
  const std::string threshold = EscapeHtml(FormatValue(kActiveThreshold));

  if (data.active_constraints_complete && !data.active_constraints.empty()) {
    // Every row of an analysis of the final design: nothing is left unknown.
    const ActiveConstraint* worst = &data.active_constraints.front();
    for (const ActiveConstraint& a : data.active_constraints) {
      if (a.normalized_value > worst->normalized_value) worst = &a;
      if (a.normalized_value > kActiveThreshold) rows.push_back({a.name, a.normalized_value, "analysis of the final design"});
    }
    std::stable_sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.value > b.value; });
    if (rows.empty()) {
      return "<p class=\"note\">No row is active at the final design: the most critical, " + EscapeHtml(worst->name) +
             ", has normalized value " + EscapeHtml(FormatValue(worst->normalized_value)) +
             " (active means above " + threshold + ").</p>\n";
    }
    return table() + "<p class=\"note\">All rows of the analysis of the final design above " + threshold +
           ", most critical first.</p>\n";
  }

  const ReportCycle* record = RecordOfFinalDesign(data);
  if (record != nullptr && !record->worst_constraint.empty() && record->max_violation_trial > kActiveThreshold) {
    rows.push_back({record->worst_constraint, record->max_violation_trial,
                    "worst row of the final design (trial point of cycle " + std::to_string(record->cycle) + ")"});
  }
  for (const ActiveConstraint& a : data.active_constraints) {
    const bool seen = std::any_of(rows.begin(), rows.end(), [&](const Row& r) { return r.name == a.name; });
    if (!seen && a.normalized_value > kActiveThreshold) rows.push_back({a.name, a.normalized_value, "job data"});
  }
  std::string out;
  if (!rows.empty()) out += table();
  // Say exactly what is known: the record keeps one row per trial point.
  if (LastAccepted(data) == nullptr) {
    out += "<p class=\"note\">No trial point has been accepted, so the rows active at the final "
           "design (the initial design) are not recorded.</p>\n";
  } else if (record == nullptr) {
    out += "<p class=\"note\">No cycle record has the final design as its trial point, so its rows are "
           "not recorded here.</p>\n";
  } else if (record->worst_constraint.empty()) {
    out += "<p class=\"note\">The study has no constraint rows.</p>\n";
  } else if (rows.empty()) {
    out += "<p class=\"note\">No row is known to be active: the most critical row at the final "
           "design, " + EscapeHtml(record->worst_constraint) + ", has normalized value " +
           EscapeHtml(FormatValue(record->max_violation_trial)) + " (active means above " + threshold + ").</p>\n";
  }
  if (record != nullptr && !record->worst_constraint.empty() && data.active_constraints.empty()) {
    out += "<p class=\"note\">The job record keeps only the most critical row (the one giving "
           "maxg) of each trial point; other rows may be active at the final design as well.</p>\n";
  }
  return out;
}

std::string CycleTableHtml(const ReportData& data) {
  if (data.records.empty()) return "<p class=\"empty\">No cycle has been recorded.</p>\n";
  std::string out =
      "<table class=\"cycles\">\n<thead><tr><th>cycle</th><th>attempt</th><th>F(x0)</th>"
      "<th>F(x*)</th><th>F~(x*)</th><th>maxg(x*)</th><th>worst row</th><th>e_o</th>"
      "<th>maxfout</th><th>worst approximation</th><th>KKT residual</th><th>feas</th><th>LP</th><th>analyses</th>"
      "<th>result</th></tr></thead>\n<tbody>\n";
  for (const ReportCycle& r : data.records) {
    std::string result;
    if (r.accepted) {
      result = r.converged ? "accepted, converged" : "accepted";
    } else {
      result = "rejected" + (r.rejection_reason.empty() ? std::string() : ": " + r.rejection_reason);
    }
    out += std::string("<tr class=\"") + (r.accepted ? "accepted" : "rejected") + "\">" +
           Cell(std::to_string(r.cycle), "num") + Cell(std::to_string(r.attempt), "num") +
           Num(r.objective_x0) +
           Cell(EscapeHtml(FormatValue(r.objective_trial, 6, "analysis failed")), "num") +
           Num(r.objective_predicted) + Num(r.max_violation_trial, 4) +
           Cell(BreakableName(r.worst_constraint), "name") + Num(r.objective_error, 4) +
           Num(r.max_approximation_error, 4) + Cell(BreakableName(r.worst_approximation), "name") +
           Num(r.optimality_residual, 3) +
           Cell(r.lp_feasible ? "yes" : "no (s = " + EscapeHtml(FormatValue(r.infeasibility, 3)) + ")") +
           Cell(EscapeHtml(r.lp_status), "name") + Cell(std::to_string(r.analyses_total), "num") +
           Cell(EscapeHtml(result), "result") + "</tr>\n";
  }
  out += "</tbody>\n</table>\n";
  return out;
}

}  // namespace mbopt::report
