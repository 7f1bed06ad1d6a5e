#include "client/report/pareto_report.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "client/report/history_plots.h"
#include "client/report/html_escape.h"
#include "client/report/number_format.h"
#include "client/report/page_head.h"
#include "client/report/report_tables.h"
#include "client/report/response_plots.h"
#include "client/report/scalar_bars.h"
#include "client/report/svg_line_plot.h"

namespace mbopt::report {
namespace {

// Beside the shared page style: dominated points and the chosen one, and
// the chosen point's run's cycle table.
constexpr const char* kFrontRowsCss = R"css(
tr.dominated td { color: #777; }
tr.chosen td { background: #fff6d5; }
tr.rejected td { background: #fdecea; }
div.wide { overflow-x: auto; }
table.cycles { font-size: 12px; width: 100%; }
table.cycles th, table.cycles td { padding: 2px 4px; }
)css";

using Point = ParetoReportData::Point;

std::string WithUnit(const std::string& name, const std::string& unit) {
  return unit.empty() ? name : name + " [" + unit + "]";
}

std::string Cell(double value, bool violated_above_zero = false) {
  const bool violated = violated_above_zero && std::isfinite(value) && value > 0;
  return std::string("<td class=\"num") + (violated ? " violated" : "") + "\">" +
         EscapeHtml(FormatValue(value, 6)) + "</td>";
}

// The points of one status as one series: the front joined by a line in
// decreasing order of the traded value, the others as markers only.
PlotSeries SeriesOf(const ParetoReportData& data, const std::string& status, const std::string& name,
                    const std::string& color, MarkerShape marker) {
  PlotSeries s;
  s.name = name;
  s.color = color;
  s.marker = marker;
  s.draw_line = status == "front";
  s.marker_radius_px = 4.0;
  std::vector<const Point*> points;
  for (const Point& p : data.points) {
    if (p.status == status) points.push_back(&p);
  }
  // Along the front, not in the points' order: points added by refinement
  // come last in number but lie between the others.
  std::stable_sort(points.begin(), points.end(), [](const Point* a, const Point* b) { return a->value > b->value; });
  for (const Point* p : points) {
    s.x.push_back(p->value);
    s.y.push_back(p->objective);
    s.point_labels.push_back(std::to_string(p->index));
  }
  return s;
}

// What the front trades the objective against, as a sentence names it.
std::string SecondObjectivePhrase(const ParetoReportData& data) {
  return (data.against_objective ? "the second objective " : "the largest value of ") + data.against;
}

std::string FrontPlot(const ParetoReportData& data) {
  PlotSpec spec;
  spec.title = "Pareto front: objective F against " + SecondObjectivePhrase(data);
  spec.x_label = WithUnit(data.against, data.against_unit);
  spec.y_label = WithUnit("F", data.objective_unit);
  spec.height_px = 420.0;
  spec.series.push_back(SeriesOf(data, "front", "on the front", "#1f77b4", MarkerShape::kCircle));
  spec.series.push_back(SeriesOf(data, "dominated", "dominated", "#7f7f7f", MarkerShape::kHollowCircle));
  spec.series.push_back(SeriesOf(data, "infeasible", "infeasible (its level not met)", "#b00020",
                                 MarkerShape::kHollowCircle));
  for (const Point& p : data.points) {
    if (p.index != data.chosen) continue;
    PlotSeries chosen;
    chosen.name = "chosen: point " + std::to_string(p.index);
    chosen.color = "#ff7f0e";
    chosen.draw_line = false;
    chosen.marker = MarkerShape::kHollowCircle;
    chosen.marker_radius_px = 9.0;
    chosen.x = {p.value};
    chosen.y = {p.objective};
    spec.series.push_back(std::move(chosen));
  }
  return "<div class=\"figure\">\n" + RenderLinePlotSvg(spec) + "</div>\n";
}

// A front of three objectives seen along one axis: the points of one
// status as markers at (x_of, y_of), labelled with their numbers. A
// surface has no order along a line, so none is drawn.
PlotSeries ProjectionSeries(const ParetoReportData& data, const std::string& status, const std::string& name,
                            const std::string& color, MarkerShape marker, double (*x_of)(const Point&),
                            double (*y_of)(const Point&)) {
  PlotSeries s;
  s.name = name;
  s.color = color;
  s.marker = marker;
  s.draw_line = false;
  s.marker_radius_px = 4.0;
  for (const Point& p : data.points) {
    if (p.status != status || !std::isfinite(x_of(p)) || !std::isfinite(y_of(p))) continue;
    s.x.push_back(x_of(p));
    s.y.push_back(y_of(p));
    s.point_labels.push_back(std::to_string(p.index));
  }
  return s;
}

double ObjectiveOf(const Point& p) { return p.objective; }
double ValueOf(const Point& p) { return p.value; }
double Value3Of(const Point& p) { return p.value3; }

std::string Projection(const ParetoReportData& data, const std::string& title, const std::string& x_label,
                       const std::string& y_label, double (*x_of)(const Point&), double (*y_of)(const Point&)) {
  PlotSpec spec;
  spec.title = title;
  spec.x_label = x_label;
  spec.y_label = y_label;
  spec.height_px = 360.0;
  spec.series.push_back(ProjectionSeries(data, "front", "on the front", "#1f77b4", MarkerShape::kCircle, x_of, y_of));
  spec.series.push_back(
      ProjectionSeries(data, "dominated", "dominated", "#7f7f7f", MarkerShape::kHollowCircle, x_of, y_of));
  for (const Point& p : data.points) {
    if (p.index != data.chosen || !std::isfinite(x_of(p)) || !std::isfinite(y_of(p))) continue;
    PlotSeries chosen;
    chosen.name = "chosen: point " + std::to_string(p.index);
    chosen.color = "#ff7f0e";
    chosen.draw_line = false;
    chosen.marker = MarkerShape::kHollowCircle;
    chosen.marker_radius_px = 9.0;
    chosen.x = {x_of(p)};
    chosen.y = {y_of(p)};
    spec.series.push_back(std::move(chosen));
  }
  return "<div class=\"figure\">\n" + RenderLinePlotSvg(spec) + "</div>\n";
}

std::string FrontProjections(const ParetoReportData& data) {
  const std::string f = WithUnit("F", data.objective_unit);
  const std::string second = WithUnit(data.against, data.against_unit);
  const std::string third = WithUnit(data.against3, data.against3_unit);
  return Projection(data, "F against " + data.against, second, f, ValueOf, ObjectiveOf) +
         Projection(data, "F against " + data.against3, third, f, Value3Of, ObjectiveOf) +
         Projection(data, data.against3 + " against " + data.against, second, third, ValueOf, Value3Of);
}

std::string PointsTable(const ParetoReportData& data) {
  std::string out = "<div class=\"wide\">\n<table>\n<thead><tr><th>point</th>";
  out += "<th>" + EscapeHtml(WithUnit("level", data.against_unit)) + "</th>";
  if (data.three) out += "<th>" + EscapeHtml(WithUnit("level3", data.against3_unit)) + "</th>";
  out += "<th>" + EscapeHtml(WithUnit("F", data.objective_unit)) + "</th>";
  out += "<th>" + EscapeHtml(WithUnit(data.against, data.against_unit)) + "</th>";
  if (data.three) out += "<th>" + EscapeHtml(WithUnit(data.against3, data.against3_unit)) + "</th>";
  out += "<th>maxg</th><th>run</th><th>cycles</th>";
  for (size_t v = 0; v < data.variable_names.size(); ++v) {
    out += "<th>" + EscapeHtml(WithUnit(data.variable_names[v], data.variable_units[v])) + "</th>";
  }
  out += "<th>status</th></tr></thead>\n<tbody>\n";
  for (const Point& p : data.points) {
    const bool failed = p.status == "failed" || p.status == "not run" || p.status == "infeasible";
    out += p.index == data.chosen       ? "<tr class=\"chosen\">"
           : failed                     ? "<tr class=\"failed\">"
           : p.status == "dominated"    ? "<tr class=\"dominated\">"
                                        : "<tr>";
    out += "<td class=\"num\">" + std::to_string(p.index) + "</td>";
    out += Cell(p.level) + (data.three ? Cell(p.level3) : "") + Cell(p.objective) + Cell(p.value) +
           (data.three ? Cell(p.value3) : "") + Cell(p.max_violation, true);
    out += "<td>" + EscapeHtml(p.run_state) + "</td><td class=\"num\">" + std::to_string(p.cycles) + "</td>";
    for (size_t v = 0; v < data.variable_names.size(); ++v) {
      out += Cell(v < p.design.size() && p.status != "not run" ? p.design[v] : std::nan(""));
    }
    out += "<td>" + EscapeHtml(p.status) + (p.reason.empty() ? "" : ": " + EscapeHtml(p.reason)) + "</td></tr>\n";
  }
  out += "</tbody>\n</table>\n</div>\n";
  return out;
}

std::string ChosenPoint(const ParetoReportData& data) {
  for (const Point& p : data.points) {
    if (p.index != data.chosen) continue;
    std::string out = "<h2>Chosen design: point " + std::to_string(p.index) + "</h2>\n<table>\n<tbody>\n";
    for (size_t v = 0; v < data.variable_names.size(); ++v) {
      out += "<tr><th>" + EscapeHtml(WithUnit(data.variable_names[v], data.variable_units[v])) + "</th>" +
             Cell(v < p.design.size() ? p.design[v] : std::nan("")) + "</tr>\n";
    }
    out += "</tbody>\n</table>\n";
    out += "<p class=\"note\">Each constraint's largest (g - limit) / scale against the study's limits "
           "(the traded constraint's too): above 0 violated.</p>\n<table>\n<tbody>\n";
    for (size_t c = 0; c < data.constraint_names.size(); ++c) {
      out += "<tr><th>" + EscapeHtml(data.constraint_names[c]) + "</th>" +
             Cell(c < p.constraints.size() ? p.constraints[c] : std::nan(""), true) + "</tr>\n";
    }
    out += "</tbody>\n</table>\n";
    return out;
  }
  return "";
}

std::string ChosenHistory(const ParetoReportData& data) {
  if (data.chosen == 0) return "";
  const ReportData& history = data.chosen_history;
  std::string out = "<h2>Cycle history of point " + std::to_string(data.chosen) + "'s run</h2>\n";
  if (history.records.empty()) {
    return out + "<p class=\"note\">" +
           EscapeHtml(data.chosen_history_note.empty() ? std::string("Its run has no cycle records.")
                                                       : data.chosen_history_note) +
           "</p>\n";
  }
  out += "<p class=\"note\">As a single job's history: each point k is the design the run accepted in cycle k "
         "(0: the design it started from); hollow red markers are rejected trial points. maxg is against the "
         "run's own limits, the point's level included.";
  if (!data.chosen_history_note.empty()) out += " " + EscapeHtml(data.chosen_history_note);
  out += "</p>\n";
  for (const PlotSpec& spec : {ObjectivePlot(history), ViolationPlot(history), ApproximationErrorPlot(history),
                               MoveLimitPlot(history), DesignVariablePlot(history)}) {
    out += "<div class=\"figure\">\n" + RenderLinePlotSvg(spec) + "</div>\n";
  }
  out += "<p class=\"note\">One row per LP solve of the run.</p>\n";
  out += "<div class=\"wide\">\n" + CycleTableHtml(history) + "</div>\n";
  return out;
}

std::string ChosenResponses(const ParetoReportData& data) {
  if (data.chosen == 0) return "";
  std::string out = "<h2>Responses of point " + std::to_string(data.chosen) + "</h2>\n";
  if (data.chosen_responses.empty()) {
    return out + "<p class=\"note\">" +
           EscapeHtml(data.chosen_responses_note.empty() ? std::string("No responses to show.")
                                                          : data.chosen_responses_note) +
           "</p>\n";
  }
  out += "<p class=\"note\">Each objective and constraint's output over time, analysed again at the study's "
         "initial design (grey, dashed) and at point " +
         std::to_string(data.chosen) +
         "'s design (blue), with the study's limits (the point's own level on the traded constraint is in the "
         "table above).</p>\n";
  for (const ResponsePlot& plot : data.chosen_responses) {
    out += "<div class=\"figure\">\n" + (plot.scalar() ? RenderScalarBarsSvg(plot) : RenderLinePlotSvg(ResponsePlotSpec(plot))) +
           "</div>\n";
    if (!plot.note.empty()) out += "<p class=\"note\">" + EscapeHtml(plot.note) + "</p>\n";
  }
  if (!data.chosen_responses_note.empty()) {
    out += "<p class=\"note\">" + EscapeHtml(data.chosen_responses_note) + "</p>\n";
  }
  return out;
}

}  // namespace

std::string RenderParetoReportHtml(const ParetoReportData& data) {
  std::string out = PageHeadHtml(data.study_name, data.description, std::string(kDesignsPageStyleCss) + kFrontRowsCss + kPlotStyleCss);
  out += "<table>\n<tbody>\n";
  if (!data.job_id.empty()) out += "<tr><th>job</th><td>" + EscapeHtml(data.job_id) + "</td></tr>\n";
  out += "<tr><th>state</th><td><strong>" + EscapeHtml(data.state) + "</strong></td></tr>\n";
  out += "<tr><th>points computed</th><td>" + std::to_string(data.points.size()) + " of " +
         std::to_string(data.points_total) + "</td></tr>\n";
  out += "<tr><th>traded against</th><td>" + EscapeHtml(SecondObjectivePhrase(data)) +
         (data.three ? " and the largest value of " + EscapeHtml(data.against3) : "") + "</td></tr>\n";
  if (!data.message.empty()) out += "<tr><th>message</th><td>" + EscapeHtml(data.message) + "</td></tr>\n";
  out += "</tbody>\n</table>\n";
  out += "<h2>Pareto front</h2>\n";
  if (data.points.empty()) {
    out += "<p class=\"note\">No point has been computed yet.</p>\n";
  } else if (data.three) {
    out += std::string("<p class=\"note\">A front of three objectives, seen along each axis in turn. Each point is "
                       "one optimization: the ") +
           (data.objective_maximized ? "greatest" : "least") + " F with " + EscapeHtml(data.against) + " and " +
           EscapeHtml(data.against3) +
           " held below the point's levels (points 1 to 3: the least F, the least " + EscapeHtml(data.against) +
           " and the least " + EscapeHtml(data.against3) +
           ", each with both levels free). Points are numbered as in the table; a point another beats in all three "
           "is dominated; infeasible points (no design meets both levels) are in the table only.</p>\n";
    out += FrontProjections(data);
  } else {
    // A maximized second objective is held above its level, and its
    // best value is the greatest.
    const bool maximized = data.against_maximized;
    out += std::string("<p class=\"note\">Each point is one optimization: the ") +
           (data.objective_maximized ? "greatest" : "least") + " F with " + EscapeHtml(data.against) +
           (maximized ? " held above" : " held below") + " the point's level (point 1: " + EscapeHtml(data.against) +
           " free; at the other end: its " + (maximized ? "greatest" : "least") +
           " value; points added where the front bends are numbered "
           "after the others). Points are numbered as in the table; a point another beats in both is "
           "dominated.</p>\n";
    out += FrontPlot(data);
  }
  out += "<h2>Points</h2>\n";
  out += PointsTable(data);
  out += ChosenPoint(data);
  out += ChosenHistory(data);
  out += ChosenResponses(data);
  out += "</body>\n</html>\n";
  return out;
}

}  // namespace mbopt::report
