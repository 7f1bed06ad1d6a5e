#include "client/report/job_report_html.h"

#include <cmath>
#include <string>

#include "client/report/history_plots.h"
#include "client/report/html_escape.h"
#include "client/report/page_head.h"
#include "client/report/mechanism_drawing.h"
#include "client/report/number_format.h"
#include "client/report/report_tables.h"
#include "client/report/response_plots.h"
#include "client/report/scalar_bars.h"
#include "client/report/svg_line_plot.h"

namespace mbopt::report {
namespace {

constexpr const char* kStyle = R"css(
body { font-family: "DejaVu Sans", "Liberation Sans", Arial, sans-serif; color: #222;
       margin: 24px; max-width: 1180px; }
h1 { font-size: 22px; margin-bottom: 4px; }
h2 { font-size: 17px; margin-top: 28px; border-bottom: 1px solid #ccc; }
p.description { color: #555; margin-top: 0; }
table { border-collapse: collapse; font-size: 13px; margin: 8px 0; }
th, td { border: 1px solid #ccc; padding: 3px 7px; text-align: left; vertical-align: top; }
th { background: #f2f2f2; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
td.on-bound { font-weight: bold; color: #8a4b00; }
tr.rejected td { background: #fdecea; }
div.wide { overflow-x: auto; }
table.cycles { font-size: 12px; width: 100%; table-layout: auto; }
table.cycles th, table.cycles td { padding: 2px 4px; }
table.cycles th { white-space: normal; }
table.cycles td.num { white-space: nowrap; }
table.cycles td.name { overflow-wrap: anywhere; min-width: 70px; }
table.cycles td.result { min-width: 120px; }
table.active td, table.design td { overflow-wrap: anywhere; }
table.summary th { width: 190px; }
p.note, p.empty { color: #555; font-size: 13px; }
)css";

std::string Row(const std::string& header, const std::string& escaped_value) {
  return "<tr><th>" + EscapeHtml(header) + "</th><td>" + escaped_value + "</td></tr>\n";
}

double FinalObjective(const ReportData& data) {
  if (std::isfinite(data.objective)) return data.objective;
  for (auto it = data.records.rbegin(); it != data.records.rend(); ++it) {
    if (it->accepted) return it->objective_trial;
  }
  return data.records.empty() ? data.objective : data.records.front().objective_x0;
}

std::string SummaryTable(const ReportData& data) {
  std::string out = "<table class=\"summary\">\n<tbody>\n";
  if (!data.job_id.empty()) out += Row("job", EscapeHtml(data.job_id));
  out += Row("state", "<strong>" + EscapeHtml(data.state.empty() ? "unknown" : data.state) + "</strong>");
  out += Row("cycles", std::to_string(data.cycles));
  out += Row("analyses", std::to_string(data.analyses));
  std::string objective = EscapeHtml(FormatValue(FinalObjective(data), 6, "not known"));
  if (!data.objective_unit.empty()) objective += " " + EscapeHtml(data.objective_unit);
  out += Row("final objective F", objective);
  out += Row("max violation maxg",
             EscapeHtml(FormatValue(data.max_violation, 4, "not known") + ViolationMark(data, data.max_violation)));
  if (data.wall_seconds > 0) out += Row("wall time", EscapeHtml(FormatValue(data.wall_seconds, 4)) + " s");
  if (!data.message.empty()) out += Row("message", EscapeHtml(data.message));
  if (!data.failed_analyses_by_kind.empty()) {
    std::string failed;
    for (const auto& [kind, count] : data.failed_analyses_by_kind) {
      failed += (failed.empty() ? "" : ", ") + EscapeHtml(kind) + " " + std::to_string(count);
    }
    out += Row("failed analyses by kind", failed);
  }
  out += "</tbody>\n</table>\n";
  return out;
}

// False when no record names a worst constraint row and every maxg is 0:
// a study without constraints (failed trials have neither).
bool HasConstraintRows(const ReportData& data) {
  for (const ReportCycle& r : data.records) {
    if (!r.worst_constraint.empty()) return true;
    for (double g : {r.max_violation_x0, r.max_violation_trial}) {
      if (std::isfinite(g) && g != 0.0) return true;
    }
  }
  return false;
}

std::string Figure(const PlotSpec& spec) {
  return "<div class=\"figure\">\n" + RenderLinePlotSvg(spec) + "</div>\n";
}

}  // namespace

std::string RenderJobReportHtml(const ReportData& data) {
  std::string out = PageHeadHtml(data.study_name, data.description, std::string(kStyle) + kPlotStyleCss);
  out += SummaryTable(data);
  out += MechanismSectionHtml(data.mechanism);

  out += "<h2>Cycle history</h2>\n";
  if (data.records.empty()) {
    out += "<p class=\"empty\">No cycle has been recorded for this job yet: there is no history "
           "to plot.</p>\n";
  } else {
    out += "<p class=\"note\">Each point k is the design accepted in cycle k (0: the initial "
           "design, which is x0 of cycle 1). Hollow red markers are trial points x* that the "
           "move-limit strategy rejected; a failed analysis leaves a gap.</p>\n";
    out += Figure(ObjectivePlot(data));
    if (HasConstraintRows(data)) {
      out += Figure(ViolationPlot(data));
    } else {
      out += "<p class=\"note\">The study has no constraint rows: maxg is 0 throughout, so there is "
             "no violation plot.</p>\n";
    }
    out += Figure(ApproximationErrorPlot(data));
    out += Figure(MoveLimitPlot(data));
    out += Figure(DesignVariablePlot(data));
  }

  out += "<h2>Responses at the initial and final designs</h2>\n";
  if (data.responses.empty()) {
    out += "<p class=\"empty\">" +
           EscapeHtml(data.responses_note.empty() ? std::string("No responses to show.") : data.responses_note) +
           "</p>\n";
  } else {
    out += "<p class=\"note\">Each objective and constraint's output over time, analysed again at the initial "
           "design (grey, dashed) and at the final design (blue), with the constraint's limits. For a "
           "multi-series output (stress at every node) the series that comes closest to its limit at the "
           "final design is shown.</p>\n";
    for (const ResponsePlot& plot : data.responses) {
      out += plot.scalar() ? "<div class=\"figure\">\n" + RenderScalarBarsSvg(plot) + "</div>\n"
                           : Figure(ResponsePlotSpec(plot));
      if (!plot.note.empty()) out += "<p class=\"note\">" + EscapeHtml(plot.note) + "</p>\n";
    }
    if (!data.responses_note.empty()) out += "<p class=\"note\">" + EscapeHtml(data.responses_note) + "</p>\n";
  }
  if (!data.xy_plots.empty()) {
    out += "<h2>Plots of one response against another</h2>\n";
    out += "<p class=\"note\">Each curve runs over the time grid from its hollow marker (t = 0): the initial "
           "design grey and dashed, the final design blue.</p>\n";
    for (const XyPlot& plot : data.xy_plots) out += Figure(XyPlotSpec(plot));
  }

  out += "<h2>Final design</h2>\n";
  out += FinalDesignTableHtml(data);
  out += "<h2>Active constraints</h2>\n";
  out += ActiveConstraintsHtml(data);
  out += "<h2>Cycles</h2>\n";
  out += "<p class=\"note\">One row per LP solve: a cycle repeats its LP with smaller move "
         "limits after each rejected trial point.</p>\n";
  out += "<div class=\"wide\">\n" + CycleTableHtml(data) + "</div>\n";
  out += "</body>\n</html>\n";
  return out;
}

}  // namespace mbopt::report
