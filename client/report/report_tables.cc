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

std::string ActiveConstraintsHtml(const ReportData& data) {
  struct Row {
    std::string name;
    double value;
    std::string source;
  };
  std::vector<Row> rows;
  const ReportCycle* last = LastAccepted(data);
  if (last != nullptr && !last->worst_constraint.empty() &&
      last->max_violation_trial > kActiveThreshold) {
    rows.push_back({last->worst_constraint, last->max_violation_trial,
                    "worst row of the last accepted trial (cycle " + std::to_string(last->cycle) + ")"});
  }
  for (const ActiveConstraint& a : data.active_constraints) {
    const bool seen = std::any_of(rows.begin(), rows.end(), [&](const Row& r) { return r.name == a.name; });
    if (!seen && a.normalized_value > kActiveThreshold) rows.push_back({a.name, a.normalized_value, "job data"});
  }
  std::string out;
  if (!rows.empty()) {
    out += "<table class=\"active\">\n<thead><tr><th>constraint row</th><th>normalized value</th>"
           "<th>source</th></tr></thead>\n<tbody>\n";
    for (const Row& r : rows) {
      out += "<tr>" + Cell(EscapeHtml(r.name)) + Num(r.value) + Cell(EscapeHtml(r.source)) + "</tr>\n";
    }
    out += "</tbody>\n</table>\n";
  }
  // Say exactly what is known: the record keeps one row per trial point.
  if (last == nullptr) {
    out += "<p class=\"note\">No trial point has been accepted, so the rows active at the final "
           "design (the initial design) are not recorded.</p>\n";
  } else if (last->worst_constraint.empty()) {
    out += "<p class=\"note\">The study has no constraint rows.</p>\n";
  } else if (rows.empty()) {
    out += "<p class=\"note\">No row is known to be active: the most critical row at the final "
           "design, " + EscapeHtml(last->worst_constraint) + ", has normalized value " +
           EscapeHtml(FormatValue(last->max_violation_trial)) + " (active means above " +
           EscapeHtml(FormatValue(kActiveThreshold)) + ").</p>\n";
  }
  if (last != nullptr && !last->worst_constraint.empty() && data.active_constraints.empty()) {
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
           Cell(EscapeHtml(r.worst_constraint)) + Num(r.objective_error, 4) +
           Num(r.max_approximation_error, 4) + Cell(EscapeHtml(r.worst_approximation)) +
           Num(r.optimality_residual, 3) +
           Cell(r.lp_feasible ? "yes" : "no (s = " + EscapeHtml(FormatValue(r.infeasibility, 3)) + ")") +
           Cell(EscapeHtml(r.lp_status)) + Cell(std::to_string(r.analyses_total), "num") +
           Cell(EscapeHtml(result)) + "</tr>\n";
  }
  out += "</tbody>\n</table>\n";
  return out;
}

}  // namespace mbopt::report
