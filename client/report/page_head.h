// The opening every report page shares: doctype, title, the page's own
// style sheet, the study's name as heading and its description.
#pragma once

#include <string>
#include <string_view>

namespace mbopt::report {

// The style of the SVG plots (svg_line_plot.h) every page with plots adds
// to its own.
inline constexpr const char* kPlotStyleCss = R"css(
div.figure { margin: 10px 0 18px 0; }
svg.plot { max-width: 100%; height: auto; font-family: "DejaVu Sans", "Liberation Sans", Arial, sans-serif; }
svg .plot-title { font-size: 14px; font-weight: bold; fill: #222; }
svg .tick { font-size: 11px; fill: #333; }
svg .axis-label { font-size: 12px; fill: #222; }
svg .legend { font-size: 12px; fill: #222; }
svg .ref-label { font-size: 10px; fill: #555; }
svg .point-label { font-size: 11px; fill: #222; }
svg .note, svg .no-data { font-size: 11px; fill: #555; }
)css";

// The page style of the reports of several designs (a design set's, a
// Pareto front's): text, headings and the designs' table.
inline constexpr const char* kDesignsPageStyleCss = R"css(
body { font-family: "DejaVu Sans", "Liberation Sans", Arial, sans-serif; color: #222;
       margin: 24px; max-width: 1180px; }
h1 { font-size: 22px; margin-bottom: 4px; }
h2 { font-size: 17px; margin-top: 28px; border-bottom: 1px solid #ccc; }
p.description, p.note { color: #555; }
p.note { font-size: 13px; }
table { border-collapse: collapse; font-size: 13px; margin: 8px 0; }
th, td { border: 1px solid #ccc; padding: 3px 7px; text-align: left; }
th { background: #f2f2f2; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
td.violated { color: #b00020; font-weight: bold; }
tr.failed td { background: #fdecea; }
div.wide { overflow-x: auto; }
)css";

// `study_name` empty reads "(unnamed study)"; `style_css` goes inline.
std::string PageHeadHtml(const std::string& study_name, const std::string& description, std::string_view style_css);

}  // namespace mbopt::report
