// The job report page of `mbopt report`: one self-contained HTML document
// (inline CSS and SVG; no scripts, fonts or other resources fetched) that
// shows a job's cycle history the way the 1994 SLP report's figures do:
// objective, maximum constraint violation, approximation errors against the
// move-limit thresholds, move-limit factors and design variables per cycle,
// the final design against its bounds, the active constraints and a table
// of every LP solve. docs/report.md explains how to read it.
#pragma once

#include <string>

#include "client/report/report_data.h"

namespace mbopt::report {

// Renders the page. Never fails: missing data (no cycles yet, failed
// analyses, no study) is shown as such on the page.
std::string RenderJobReportHtml(const ReportData& data);

}  // namespace mbopt::report
