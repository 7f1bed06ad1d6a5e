#include "client/report/history_plots.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "client/report/number_format.h"

namespace mbopt::report {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr const char* kRejectedColor = "#d62728";
constexpr const char* kXLabel = "cycle (0: initial design; k: design accepted in cycle k)";

struct CycleGroup {
  int cycle = 0;
  const ReportCycle* accepted = nullptr;
  std::vector<const ReportCycle*> rejected;
};

std::vector<CycleGroup> GroupByCycle(const ReportData& data) {
  std::vector<CycleGroup> groups;
  for (const ReportCycle& r : data.records) {
    if (groups.empty() || groups.back().cycle != r.cycle) groups.push_back({r.cycle, nullptr, {}});
    if (r.accepted) {
      groups.back().accepted = &r;
    } else {
      groups.back().rejected.push_back(&r);
    }
  }
  return groups;
}

bool UseLog(ScaleChoice choice, const std::vector<double>& values) {
  switch (choice) {
    case ScaleChoice::kLinear: return false;
    case ScaleChoice::kLog: return true;
    case ScaleChoice::kAuto: return SpansDecades(values, 2.0);
  }
  return false;
}

double At(const std::vector<double>& v, int i) {
  return i >= 0 && static_cast<std::size_t>(i) < v.size() ? v[static_cast<std::size_t>(i)] : kNaN;
}

int VariableCount(const ReportData& data) {
  std::size_t n = data.variables.size();
  for (const ReportCycle& r : data.records) {
    n = std::max({n, r.x0_scaled.size(), r.x_trial_scaled.size(), r.move_limits.size()});
  }
  return static_cast<int>(n);
}

// The accepted history of one quantity: its value at the initial design
// (from the first record) and after every cycle with an accepted trial.
PlotSeries AcceptedHistory(const ReportData& data, const std::string& name, const std::string& color,
                           double (*at_x0)(const ReportCycle&), double (*at_trial)(const ReportCycle&)) {
  PlotSeries s;
  s.name = name;
  s.color = color;
  if (!data.records.empty()) {
    s.x.push_back(0);
    s.y.push_back(at_x0(data.records.front()));
  }
  for (const CycleGroup& g : GroupByCycle(data)) {
    s.x.push_back(g.cycle);
    s.y.push_back(g.accepted != nullptr ? at_trial(*g.accepted) : kNaN);
  }
  return s;
}

PlotSeries RejectedPoints(const ReportData& data, const std::string& name, const std::string& color,
                          double (*at_trial)(const ReportCycle&)) {
  PlotSeries s;
  s.name = name;
  s.color = color;
  s.draw_line = false;
  s.marker = MarkerShape::kHollowCircle;
  s.marker_radius_px = 4.5;
  for (const ReportCycle& r : data.records) {
    if (r.accepted) continue;
    s.x.push_back(r.cycle);
    s.y.push_back(at_trial(r));
  }
  return s;
}

std::vector<double> AllY(const PlotSpec& spec) {
  std::vector<double> all;
  for (const PlotSeries& s : spec.series) all.insert(all.end(), s.y.begin(), s.y.end());
  return all;
}

PlotSpec BasePlot(const std::string& title, const std::string& y_label) {
  PlotSpec spec;
  spec.title = title;
  spec.x_label = kXLabel;
  spec.y_label = y_label;
  spec.x_min_step = 1.0;
  return spec;
}

// Design variable i's line: its name, and a colour and dash of its own.
PlotSeries VariableSeries(const ReportData& data, int i) {
  PlotSeries s;
  s.name = VariableName(data, i);
  s.color = SeriesColor(i);
  s.dash = SeriesDash(i);
  return s;
}

}  // namespace

std::string SeriesColor(int k) {
  static const char* const kPalette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b",
                                         "#e377c2", "#7f7f7f", "#bcbd22", "#17becf", "#393b79"};
  return kPalette[static_cast<std::size_t>(k) % 10];
}

std::string SeriesDash(int k) {
  static const char* const kDashes[] = {"", "7 3", "2 3", "9 3 2 3"};
  return kDashes[static_cast<std::size_t>(k / 10) % 4];
}

std::string VariableName(const ReportData& data, int i) {
  if (i >= 0 && static_cast<std::size_t>(i) < data.variables.size() &&
      !data.variables[static_cast<std::size_t>(i)].name.empty()) {
    return data.variables[static_cast<std::size_t>(i)].name;
  }
  return "x" + std::to_string(i + 1);
}

PlotSpec ObjectivePlot(const ReportData& data) {
  const std::string unit = data.objective_unit.empty() ? "" : " [" + data.objective_unit + "]";
  PlotSpec spec = BasePlot("Objective F", "F" + unit);
  spec.series.push_back(AcceptedHistory(
      data, "F of the design", SeriesColor(0), [](const ReportCycle& r) { return r.objective_x0; },
      [](const ReportCycle& r) { return r.objective_trial; }));
  spec.series.push_back(RejectedPoints(data, "rejected trial F(x*)", kRejectedColor,
                                       [](const ReportCycle& r) { return r.objective_trial; }));
  // A log axis only makes sense for an objective that stays positive.
  const std::vector<double> values = AllY(spec);
  const bool all_positive = std::all_of(values.begin(), values.end(),
                                        [](double v) { return !std::isfinite(v) || v > 0; });
  spec.log_y = data.objective_scale == ScaleChoice::kLog ||
               (data.objective_scale == ScaleChoice::kAuto && all_positive && UseLog(ScaleChoice::kAuto, values));
  return spec;
}

PlotSpec ViolationPlot(const ReportData& data) {
  PlotSpec spec = BasePlot("Maximum constraint violation maxg", "maxg (normalized, > 0 violated)");
  spec.series.push_back(AcceptedHistory(
      data, "maxg of the design", SeriesColor(0),
      [](const ReportCycle& r) { return r.max_violation_x0; },
      [](const ReportCycle& r) { return r.max_violation_trial; }));
  spec.series.push_back(RejectedPoints(data, "rejected trial maxg", kRejectedColor,
                                       [](const ReportCycle& r) { return r.max_violation_trial; }));
  spec.log_y = UseLog(data.violation_scale, AllY(spec));
  spec.reference_lines.push_back({kViolationRejectAbove, "0.10 reject (feasible LP)", "#d62728", true});
  spec.reference_lines.push_back(
      {data.violation_tolerance, FormatValue(data.violation_tolerance, 4) + " converged below", "#2ca02c", false});
  if (!spec.log_y) spec.reference_lines.push_back({0.0, "0 limit", "#444444", true, true});
  return spec;
}

PlotSpec ApproximationErrorPlot(const ReportData& data) {
  PlotSpec spec = BasePlot("Approximation errors of the accepted trial points", "relative error");
  auto accepted_only = [&](const std::string& name, const std::string& color,
                           double (*value)(const ReportCycle&)) {
    PlotSeries s;
    s.name = name;
    s.color = color;
    for (const CycleGroup& g : GroupByCycle(data)) {
      s.x.push_back(g.cycle);
      s.y.push_back(g.accepted != nullptr ? value(*g.accepted) : kNaN);
    }
    return s;
  };
  spec.series.push_back(accepted_only("maxfout", SeriesColor(0),
                                      [](const ReportCycle& r) { return r.max_approximation_error; }));
  spec.series.push_back(accepted_only("e_o (objective)", SeriesColor(1),
                                      [](const ReportCycle& r) { return r.objective_error; }));
  spec.series.push_back(accepted_only("KKT residual", SeriesColor(2),
                                      [](const ReportCycle& r) { return r.optimality_residual; }));
  spec.series.push_back(RejectedPoints(data, "rejected trial maxfout", kRejectedColor,
                                       [](const ReportCycle& r) { return r.max_approximation_error; }));
  PlotSeries rejected_eo = RejectedPoints(data, "rejected trial e_o", SeriesColor(1),
                                          [](const ReportCycle& r) { return r.objective_error; });
  rejected_eo.marker_radius_px = 3.5;
  spec.series.push_back(rejected_eo);
  spec.log_y = UseLog(data.error_scale, AllY(spec));
  spec.reference_lines.push_back({kErrorWidenBelow, "0.10 widen below", "#2ca02c", true});
  spec.reference_lines.push_back({kErrorNarrowAbove, "0.25 narrow above", "#ff7f0e", true, false, true});
  spec.reference_lines.push_back({kErrorRejectAbove, "0.40 reject above", "#d62728", true});
  return spec;
}

PlotSpec MoveLimitPlot(const ReportData& data) {
  PlotSpec spec = BasePlot("Move-limit factors f_i used by the LP of each cycle", "f_i");
  const int n = VariableCount(data);
  const std::vector<CycleGroup> groups = GroupByCycle(data);
  for (int i = 0; i < n; ++i) {
    PlotSeries s = VariableSeries(data, i);
    PlotSeries rejected = s;
    rejected.draw_line = false;
    rejected.marker = MarkerShape::kHollowCircle;
    rejected.marker_radius_px = 4.0;
    rejected.in_legend = false;
    for (const CycleGroup& g : groups) {
      s.x.push_back(g.cycle);
      s.y.push_back(g.accepted != nullptr ? At(g.accepted->move_limits, i) : kNaN);
      for (const ReportCycle* r : g.rejected) {
        rejected.x.push_back(g.cycle);
        rejected.y.push_back(At(r->move_limits, i));
      }
    }
    spec.series.push_back(std::move(s));
    if (!rejected.x.empty()) spec.series.push_back(std::move(rejected));
  }
  if (n > 0 && spec.series.size() > static_cast<std::size_t>(n)) {
    PlotSeries key;
    key.name = "(hollow: rejected attempt)";
    key.color = "#555555";
    key.draw_line = false;
    key.marker = MarkerShape::kHollowCircle;
    key.marker_radius_px = 4.0;
    spec.series.push_back(key);
  }
  spec.log_y = UseLog(data.move_limit_scale, AllY(spec));
  return spec;
}

PlotSpec DesignVariablePlot(const ReportData& data) {
  PlotSpec spec = BasePlot("Design variables (scaled)", "x_i (scaled)");
  const int n = VariableCount(data);
  const std::vector<CycleGroup> groups = GroupByCycle(data);
  for (int i = 0; i < n; ++i) {
    PlotSeries s = VariableSeries(data, i);
    if (!data.records.empty()) {
      s.x.push_back(0);
      s.y.push_back(At(data.records.front().x0_scaled, i));
    }
    for (const CycleGroup& g : groups) {
      s.x.push_back(g.cycle);
      s.y.push_back(g.accepted != nullptr ? At(g.accepted->x_trial_scaled, i) : kNaN);
    }
    spec.series.push_back(std::move(s));
  }
  spec.height_px = 340;
  return spec;
}

}  // namespace mbopt::report
