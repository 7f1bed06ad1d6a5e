#include "client/report/design_set_report.h"

#include <cmath>
#include <map>
#include <string>

#include "client/report/html_escape.h"
#include "client/report/page_head.h"
#include "client/report/number_format.h"
#include "client/report/svg_line_plot.h"

namespace mbopt::report {
namespace {

// Distinguishable colours for a grid's curves, repeated beyond ten.
constexpr const char* kColors[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                                   "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};

using Design = DesignSetReportData::Design;
using ConstraintInUnit = DesignSetReportData::ConstraintInUnit;

std::string Label(const DesignSetReportData& data, int variable) {
  const std::string& unit = data.variable_units[static_cast<size_t>(variable)];
  return data.variable_names[static_cast<size_t>(variable)] + (unit.empty() ? "" : " [" + unit + "]");
}

double ValueOf(const Design& d, int variable) {
  return static_cast<size_t>(variable) < d.values.size() ? d.values[static_cast<size_t>(variable)] : std::nan("");
}

// `value(design)` against the swept variable: one curve for a line, one per
// value of the second variable for a grid, points against `x_variable` for
// a sample.
template <typename Value>
std::vector<PlotSeries> Curves(const DesignSetReportData& data, int x_variable, Value value) {
  std::vector<PlotSeries> series;
  if (data.swept.size() == 2) {
    std::map<double, size_t> by_second;
    for (const Design& d : data.designs) {
      const double second = ValueOf(d, data.swept[1]);
      auto [it, added] = by_second.emplace(second, series.size());
      if (added) {
        PlotSeries s;
        s.name = data.variable_names[static_cast<size_t>(data.swept[1])] + " = " + FormatValue(second, 6);
        s.color = kColors[series.size() % 10];
        series.push_back(std::move(s));
      }
      series[it->second].x.push_back(ValueOf(d, x_variable));
      series[it->second].y.push_back(value(d));
    }
    return series;
  }
  PlotSeries s;
  s.in_legend = false;
  s.draw_line = !data.swept.empty();
  for (const Design& d : data.designs) {
    s.x.push_back(ValueOf(d, x_variable));
    s.y.push_back(value(d));
  }
  series.push_back(std::move(s));
  return series;
}

std::string Figure(const PlotSpec& spec) { return "<div class=\"figure\">\n" + RenderLinePlotSvg(spec) + "</div>\n"; }

std::string Plots(const DesignSetReportData& data) {
  std::string out;
  std::vector<int> x_variables = data.swept;
  if (data.swept.size() == 2) x_variables = {data.swept[0]};
  if (data.swept.empty()) {
    for (size_t v = 0; v < data.variable_names.size(); ++v) x_variables.push_back(static_cast<int>(v));
  }
  const std::string f_label = "F" + (data.objective_unit.empty() ? "" : " [" + data.objective_unit + "]");
  for (int x : x_variables) {
    PlotSpec objective;
    objective.title = "Objective F against " + data.variable_names[static_cast<size_t>(x)];
    objective.x_label = Label(data, x);
    objective.y_label = f_label;
    objective.series = Curves(data, x, [](const Design& d) { return d.objective; });
    out += Figure(objective);
  }
  // Constraints only against the swept variable (a sample's designs move
  // every variable at once: one scatter per variable is the objective's).
  if (data.swept.empty()) return out;
  const int x = data.swept[0];
  for (size_t c = 0; c < data.constraint_names.size(); ++c) {
    const ConstraintInUnit in_unit =
        c < data.constraints_in_unit.size() ? data.constraints_in_unit[c] : ConstraintInUnit{};
    PlotSpec constraint;
    constraint.title = "Constraint " + data.constraint_names[c] + " against " +
                       data.variable_names[static_cast<size_t>(x)];
    constraint.x_label = Label(data, x);
    constraint.series = Curves(data, x, [c, &in_unit](const Design& d) {
      const double n = c < d.constraints.size() ? d.constraints[c] : std::nan("");
      return in_unit.known ? in_unit.limit + in_unit.per_normalized * n : n;
    });
    ReferenceLine limit;
    limit.color = "#b00020";
    if (in_unit.known) {
      constraint.y_label = in_unit.quantity + (in_unit.unit.empty() ? "" : " [" + in_unit.unit + "]");
      limit.y = in_unit.limit;
      limit.label = "limit " + FormatValue(in_unit.limit, 6) + (in_unit.unit.empty() ? "" : " " + in_unit.unit) +
                    (in_unit.per_normalized < 0 ? ": below it violated" : ": above it violated");
    } else {
      constraint.y_label = "(g - limit) / scale";
      limit.y = 0.0;
      limit.label = "limit: above it violated";
    }
    constraint.reference_lines.push_back(limit);
    out += Figure(constraint);
  }
  return out;
}

std::string Cell(double value, bool violated_above_zero = false) {
  const bool violated = violated_above_zero && std::isfinite(value) && value > 0;
  return std::string("<td class=\"num") + (violated ? " violated" : "") + "\">" +
         EscapeHtml(FormatValue(value, 6)) + "</td>";
}

std::string Table(const DesignSetReportData& data) {
  std::string out = "<div class=\"wide\">\n<table>\n<thead><tr><th>design</th>";
  for (size_t v = 0; v < data.variable_names.size(); ++v) out += "<th>" + EscapeHtml(Label(data, static_cast<int>(v))) + "</th>";
  out += "<th>" + EscapeHtml("F" + (data.objective_unit.empty() ? "" : " [" + data.objective_unit + "]")) + "</th>";
  out += "<th>maxg</th>";
  for (const std::string& c : data.constraint_names) out += "<th>" + EscapeHtml(c) + "</th>";
  out += "<th>status</th></tr></thead>\n<tbody>\n";
  for (const Design& d : data.designs) {
    out += d.status == "ok" ? "<tr>" : "<tr class=\"failed\">";
    out += "<td class=\"num\">" + std::to_string(d.index) + "</td>";
    for (size_t v = 0; v < data.variable_names.size(); ++v) out += Cell(ValueOf(d, static_cast<int>(v)));
    out += Cell(d.objective) + Cell(d.max_violation, true);
    for (size_t c = 0; c < data.constraint_names.size(); ++c) {
      out += Cell(c < d.constraints.size() ? d.constraints[c] : std::nan(""), true);
    }
    out += "<td>" + EscapeHtml(d.status) +
           (d.failure_reason.empty() ? "" : ": " + EscapeHtml(d.failure_reason)) + "</td></tr>\n";
  }
  out += "</tbody>\n</table>\n</div>\n";
  return out;
}

}  // namespace

std::string RenderDesignSetReportHtml(const DesignSetReportData& data) {
  std::string out = PageHeadHtml(data.study_name, data.description, std::string(kDesignsPageStyleCss) + kPlotStyleCss);
  out += "<table>\n<tbody>\n";
  if (!data.job_id.empty()) out += "<tr><th>job</th><td>" + EscapeHtml(data.job_id) + "</td></tr>\n";
  out += "<tr><th>state</th><td><strong>" + EscapeHtml(data.state) + "</strong></td></tr>\n";
  out += "<tr><th>designs analysed</th><td>" + std::to_string(data.designs.size()) + " of " +
         std::to_string(data.designs_total) + "</td></tr>\n";
  if (!data.message.empty()) out += "<tr><th>message</th><td>" + EscapeHtml(data.message) + "</td></tr>\n";
  out += "</tbody>\n</table>\n";
  out += "<h2>Objective and constraints against the design</h2>\n";
  if (data.designs.empty()) {
    out += "<p class=\"note\">No design has been analysed yet.</p>\n";
  } else {
    out += "<p class=\"note\">Each point is one design's analysis; a failed analysis leaves a gap. A "
           "constraint with one limit is drawn in its unit: its largest value (of |value| for a MAX_ABS "
           "constraint), or its least for a lower limit, against the limit line. Any other is drawn as its "
           "largest (g - limit) / scale over its rows, violated above the limit line at 0. The table gives "
           "every constraint as (g - limit) / scale.</p>\n";
    out += Plots(data);
  }
  out += "<h2>Designs</h2>\n";
  out += Table(data);
  out += "</body>\n</html>\n";
  return out;
}

}  // namespace mbopt::report
