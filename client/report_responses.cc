#include "client/report_responses.h"

#include <google/protobuf/text_format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <set>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "client/local_cluster.h"
#include "client/study_text.h"
#include "client/subprocess.h"
#include "client/temp_dir.h"
#include "mbopt/v1/series.pb.h"
#include "spec/io/study_io.h"
#include "spec/layout.h"

namespace mbopt::client {
namespace {

// An analysis may take as long as the scene allows; this only guards a hang.
constexpr std::chrono::minutes kAnalysisGuard{30};
// A page with more plots than this is not read: the rest are counted.
constexpr int kMaxPlots = 24;

// Runs the worker's eval at scaled design `x` and reads the series it writes.
absl::StatusOr<v1::AnalysisSeries> Analyse(const std::string& worker, const std::string& study_path,
                                           const spec::Study& study, const std::vector<double>& x,
                                           const std::string& series_path) {
  std::vector<std::string> argv = {worker, "eval", study_path, "--series-out", series_path};
  for (size_t k = 0; k < x.size(); ++k) {
    argv.push_back("--set");
    // 17 digits: the design the job reached, bit for bit.
    argv.push_back(absl::StrFormat("%s=%.17g", study.variables[k].name, x[k]));
  }
  SpawnOptions options;
  options.capture_stdout = true;
  options.capture_stderr = true;
  absl::StatusOr<Subprocess> child = Subprocess::Start(argv, options);
  if (!child.ok()) return child.status();
  absl::StatusOr<Subprocess::Output> output = child->Communicate(kAnalysisGuard);
  if (!output.ok()) return output.status();
  v1::AnalysisSeries series;
  std::ifstream file(series_path, std::ios::binary);
  if (!file || !series.ParseFromIstream(&file)) {
    return absl::InternalError(absl::StrCat("mbopt-worker eval wrote no series (exit ", output->exit_code, "): ",
                                            output->stderr_text));
  }
  if (!series.failure().empty()) return absl::FailedPreconditionError(series.failure());
  return series;
}

// The series of `signal` a plot shows: the one with the largest |value| at
// the final design (a stress has one per node).
int LargestSeries(const v1::AnalysisSeries& final, int signal) {
  const v1::SignalSeries& b = final.signals(signal);
  int pick = 0;
  double largest = -1.0;
  for (int s = 0; s < b.series_size(); ++s) {
    for (double v : b.series(s).values_si()) {
      if (std::abs(v) > largest) {
        largest = std::abs(v);
        pick = s;
      }
    }
  }
  return pick;
}

// One signal's plot: the series that comes closest to its limit at the
// final design (the largest |value| without limits), in `unit`.
report::ResponsePlot SignalPlot(const v1::AnalysisSeries& initial, const v1::AnalysisSeries& final, int signal,
                                double si_per_unit, const std::string& unit, const std::string& title) {
  report::ResponsePlot plot;
  plot.title = title;
  plot.unit = unit;
  const v1::SignalSeries& a = initial.signals(signal);
  const v1::SignalSeries& b = final.signals(signal);
  const int pick = LargestSeries(final, signal);
  if (b.series_size() > 1 && pick < b.labels_size()) plot.title += " [" + b.labels(pick) + "]";
  const auto& values_a = a.series(pick).values_si();
  const auto& values_b = b.series(pick).values_si();
  if (values_b.size() == 1) {
    plot.times_s = {final.times_s_size() > 0 ? final.times_s(final.times_s_size() - 1) : 0.0};
  } else {
    plot.times_s.assign(final.times_s().begin(), final.times_s().end());
  }
  for (double v : values_a) plot.initial.push_back(v / si_per_unit);
  for (double v : values_b) plot.final.push_back(v / si_per_unit);
  return plot;
}

std::string AxisLabel(const spec::Study& study, int signal, const std::string& unit) {
  const std::string shown = unit.empty() ? spec::SiUnitName(spec::SignalDimension(study, signal)) : unit;
  return study.SignalName(signal) + (shown.empty() ? " (SI)" : " [" + shown + "]");
}

// y against x at both designs. A multi-series y shows its largest series,
// and x the series of the same index when it has as many, else its first.
// Empty curves (the plot then says "no data") when the signals' lengths
// differ, e.g. a scalar against a time series.
report::XyPlot MakeXyPlot(const spec::Study& study, const spec::XyPlot& p, const v1::AnalysisSeries& initial,
                          const v1::AnalysisSeries& final) {
  report::XyPlot plot;
  const int y_series = LargestSeries(final, p.y);
  const int x_series = final.signals(p.x).series_size() > y_series ? y_series : 0;
  plot.title = study.SignalName(p.y) + " against " + study.SignalName(p.x);
  if (final.signals(p.y).series_size() > 1 && y_series < final.signals(p.y).labels_size()) {
    plot.title += " [" + final.signals(p.y).labels(y_series) + "]";
  }
  plot.x_label = AxisLabel(study, p.x, p.x_unit);
  plot.y_label = AxisLabel(study, p.y, p.y_unit);
  auto curve = [&](const v1::AnalysisSeries& a, std::vector<double>* xs, std::vector<double>* ys) {
    const auto& x = a.signals(p.x).series(x_series).values_si();
    const auto& y = a.signals(p.y).series(y_series).values_si();
    if (x.size() != y.size()) return;
    for (int i = 0; i < x.size(); ++i) {
      xs->push_back(x[i] / p.x_si_per_unit);
      ys->push_back(y[i] / p.y_si_per_unit);
    }
  };
  curve(initial, &plot.initial_x, &plot.initial_y);
  curve(final, &plot.final_x, &plot.final_y);
  return plot;
}

// The last grid instant in `window` (where a FINAL reduction looks).
double LastInstantIn(const spec::TimeWindow& window, const std::vector<double>& instants_s) {
  double last = std::numeric_limits<double>::quiet_NaN();
  for (double t : instants_s) {
    if ((!window.from_s || t >= *window.from_s) && (!window.to_s || t <= *window.to_s)) last = t;
  }
  return last;
}

// Every constraint row at the final design (normalized, > 0 violated):
// those above the active threshold and the most critical one, so the page
// lists what is active there rather than what the cycle records kept.
void AddFinalDesignRows(const spec::Study& study, const spec::StudyLayout& layout, const v1::AnalysisSeries& final,
                        report::ReportData* data) {
  std::vector<std::vector<std::vector<double>>> series(static_cast<size_t>(final.signals_size()));
  std::vector<const std::vector<std::vector<double>>*> outputs;
  for (int k = 0; k < final.signals_size(); ++k) {
    for (const v1::SeriesValues& v : final.signals(k).series()) {
      series[static_cast<size_t>(k)].emplace_back(v.values_si().begin(), v.values_si().end());
    }
    outputs.push_back(&series[static_cast<size_t>(k)]);
  }
  absl::StatusOr<spec::StudyValues> values = spec::ComputeStudyValues(study, layout, outputs);
  if (!values.ok() || layout.rows.empty()) return;
  data->active_constraints.clear();
  for (size_t h = 0; h < layout.rows.size(); ++h) {
    const spec::ConstraintRow& row = layout.rows[h];
    const double normalized = (values->constraint_values[h] - row.limit_si) / row.scale;
    if (normalized > report::kActiveThreshold || static_cast<int>(h) == values->worst_row) {
      data->active_constraints.push_back({row.name, normalized});
    }
  }
  data->active_constraints_complete = true;
}

}  // namespace

double ViolationToleranceOf(const spec::Study& study) {
  if (study.optimizer.convergence_violation_tolerance) return *study.optimizer.convergence_violation_tolerance;
  double tolerance = report::kDefaultViolationTolerance;
  for (const spec::Constraint& c : study.constraints) {
    if (!c.equals.has_value() || !c.lower.has_value() || !c.upper.has_value()) continue;
    const double quarter_band_si = 0.25 * (*c.upper - *c.lower) * c.si_per_unit;
    tolerance = std::min(tolerance, quarter_band_si / spec::EqualityRowScale(c));
  }
  return tolerance;
}

void SetViolationTolerance(const v1::GetJobResponse& job, report::ReportData* data) {
  absl::StatusOr<spec::Study> study = spec::io::StudyFromProto(job.study(), "the job's study");
  if (study.ok()) data->violation_tolerance = ViolationToleranceOf(*study);
}

absl::StatusOr<std::vector<spec::XyPlot>> PlotsFromCommandLine(const spec::Study& study,
                                                               const std::vector<std::string>& plot_args) {
  std::vector<spec::XyPlot> plots;
  for (const std::string& arg : plot_args) {
    const size_t colon = arg.find(':');
    if (colon == std::string::npos || arg.find(':', colon + 1) != std::string::npos) {
      return absl::InvalidArgumentError(absl::StrCat("--plot ", arg, ": expected X:Y, two output or response names"));
    }
    spec::XyPlot plot;
    for (const auto& [name, index] : {std::pair{arg.substr(0, colon), &plot.x}, std::pair{arg.substr(colon + 1), &plot.y}}) {
      *index = study.FindSignal(name);
      if (*index < 0) {
        // Named in full up to a point: a message is read, not scrolled.
        constexpr int kListed = 20;
        std::vector<std::string> names;
        for (int s = 0; s < study.num_signals() && s < kListed; ++s) names.push_back("\"" + study.SignalName(s) + "\"");
        const int more = study.num_signals() - kListed;
        return absl::InvalidArgumentError(absl::StrCat("--plot ", arg, ": unknown output \"", name,
                                                       "\"; the study's outputs and responses: ",
                                                       names.empty() ? "(none)" : absl::StrJoin(names, ", "),
                                                       more > 0 ? absl::StrCat(" and ", more, " more") : ""));
      }
    }
    plots.push_back(plot);
  }
  return plots;
}

absl::Status AddResponsePlots(const v1::GetJobResponse& job, const std::vector<std::string>& plot_args,
                              report::ReportData* data) {
  const v1::JobSummary& summary = job.summary();
  absl::StatusOr<spec::Study> loaded = spec::io::StudyFromProto(job.study(), "the job's study");
  if (!loaded.ok()) {
    data->responses_note = "The job's study could not be read: " + std::string(loaded.status().message());
    return absl::OkStatus();
  }
  const spec::Study& study = *loaded;
  data->violation_tolerance = ViolationToleranceOf(study);
  absl::StatusOr<std::vector<spec::XyPlot>> extra_plots = PlotsFromCommandLine(study, plot_args);
  if (!extra_plots.ok()) return extra_plots.status();
  std::vector<spec::XyPlot> xy_plots = study.plots;
  xy_plots.insert(xy_plots.end(), extra_plots->begin(), extra_plots->end());
  if (job.cycles_size() == 0 || summary.design_size() != static_cast<int>(study.variables.size())) {
    data->responses_note = "The job has no analysed design yet.";
    return absl::OkStatus();
  }
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(study);
  absl::StatusOr<std::string> worker = FindMboptBinary("mbopt-worker", "MBOPT_WORKER_BIN", "worker/main");
  if (!layout.ok() || !worker.ok()) {
    data->responses_note = "The responses cannot be analysed here: " +
                           std::string((!layout.ok() ? layout.status() : worker.status()).message());
    return absl::OkStatus();
  }
  std::vector<double> x0, x_final;
  for (int k = 0; k < summary.design_size(); ++k) {
    const spec::DesignVariable& v = study.variables[static_cast<size_t>(k)];
    x0.push_back(v.initial);
    x_final.push_back(summary.design(k) / v.scale);
  }
  TempDir dir;
  std::string text;
  google::protobuf::TextFormat::PrintToString(job.study(), &text);
  const std::string study_path = dir.path() + "/study.study.textproto";
  std::ofstream(study_path) << text;
  std::fprintf(stderr, "analysing the initial and the final design for the response plots ...\n");
  absl::StatusOr<v1::AnalysisSeries> initial = Analyse(*worker, study_path, study, x0, dir.path() + "/initial.pb");
  absl::StatusOr<v1::AnalysisSeries> final = Analyse(*worker, study_path, study, x_final, dir.path() + "/final.pb");
  for (const auto* result : {&initial, &final}) {
    if (!result->ok()) {
      data->responses_note = absl::StrCat("The responses are not shown: the analysis at the ",
                                          result == &initial ? "initial" : "final", " design failed: ",
                                          result->status().message());
      return absl::OkStatus();
    }
  }
  if (initial->signals_size() != study.num_signals() || final->signals_size() != study.num_signals()) {
    data->responses_note = "The responses are not shown: the analyses returned another number of signals.";
    return absl::OkStatus();
  }

  // The objective's outputs first, each once.
  const spec::Objective& objective = study.objective;
  std::set<int> shown;
  auto objective_plot = [&](int signal, spec::Reduction reduction, const spec::TimeWindow& window,
                            double si_per_unit, const std::string& unit) {
    if (signal < 0 || !shown.insert(signal).second) return;
    data->responses.push_back(SignalPlot(*initial, *final, signal, si_per_unit, unit,
                                         absl::StrCat(objective.maximize ? "objective (maximized): " : "objective: ",
                                                      ReductionName(reduction), " of ",
                                                      study.SignalName(signal), WindowText(window))));
  };
  switch (objective.form) {
    case spec::Objective::Form::kMinimizeMaxOf:
    case spec::Objective::Form::kMinimize:
      objective_plot(objective.output, objective.reduction, objective.window, objective.si_per_unit, objective.unit);
      break;
    case spec::Objective::Form::kWeightedSum:
    case spec::Objective::Form::kMaxOver:
      for (const spec::WeightedTerm& t : objective.sum_terms) {
        objective_plot(t.output, t.reduction, t.window, t.si_per_unit, t.unit);
      }
      break;
    case spec::Objective::Form::kTargetDistance:
      for (const spec::TargetTerm& t : objective.terms) {
        objective_plot(t.output, spec::Reduction::kFinal, {}, t.si_per_unit, t.unit);
      }
      break;
    case spec::Objective::Form::kFeasible:
      break;  // no objective: the constraints' plots follow
  }

  int left_out = 0;
  for (size_t k = 0; k < study.constraints.size(); ++k) {
    const spec::Constraint& c = study.constraints[k];
    if (static_cast<int>(data->responses.size()) >= kMaxPlots) {
      ++left_out;
      continue;
    }
    const std::string unit = c.unit.empty() ? "" : " " + c.unit;
    std::string bound;
    std::vector<report::ResponsePlot::Limit> limits;
    const bool whole = spec::IsWholeSeriesReduction(c.reduction);
    // A limit is drawn over the instants its rows hold at: the window, or
    // the window's last instant for a bound on the final value.
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const double from_s = c.window.from_s.value_or(-kInf), to_s = c.window.to_s.value_or(kInf);
    if (!whole) {
      bound = absl::StrFormat("%s %g%s", c.reduction == spec::Reduction::kMin ? ">=" : "<=", c.limit, unit);
      limits.push_back({c.limit, c.reduction == spec::Reduction::kMin ? "lower limit" : "limit", from_s, to_s});
      if (c.reduction == spec::Reduction::kMaxAbs) limits.push_back({-c.limit, "-limit", from_s, to_s});
    } else {
      if (c.lower) bound += absl::StrFormat(">= %g%s", *c.lower, unit);
      if (c.upper) bound += absl::StrFormat("%s<= %g%s", bound.empty() ? "" : ", ", *c.upper, unit);
      // A bound on the final value is a level on the curve at one instant;
      // one on an RMS, mean, integral or range is not, and is stated in the
      // note instead.
      if (c.reduction == spec::Reduction::kFinal) {
        const double at_s = LastInstantIn(c.window, layout->instants_s);
        if (c.lower) limits.push_back({*c.lower, "lower", at_s, at_s});
        if (c.upper) limits.push_back({*c.upper, "upper", at_s, at_s});
      }
    }
    report::ResponsePlot plot =
        SignalPlot(*initial, *final, c.output, c.si_per_unit, c.unit,
                   absl::StrCat(c.name, ": ", ReductionName(c.reduction), " of ", study.SignalName(c.output),
                                WindowText(c.window), " ", bound));
    plot.limits = std::move(limits);
    if (whole && c.reduction != spec::Reduction::kFinal) {
      // The reduced value at both designs, from the layout's own reference.
      for (const spec::ConstraintRow& row : layout->rows) {
        if (row.constraint != static_cast<int>(k) || row.value.sign < 0) continue;
        auto reduced = [&](const v1::AnalysisSeries& series) {
          const auto& values = series.signals(c.output).series(row.value.series).values_si();
          return spec::RefValue(row.value, std::vector<double>(values.begin(), values.end()), layout->instants_s) /
                 c.si_per_unit;
        };
        plot.note = absl::StrFormat("%s%s: %.6g%s at the initial design, %.6g%s at the final design (%s).",
                                    ReductionName(c.reduction), WindowText(c.window), reduced(*initial), unit,
                                    reduced(*final), unit, bound);
        break;
      }
    }
    data->responses.push_back(std::move(plot));
  }
  if (left_out > 0) {
    data->responses_note = absl::StrCat(left_out, " more constraints are not plotted.");
  }
  for (const spec::XyPlot& p : xy_plots) data->xy_plots.push_back(MakeXyPlot(study, p, *initial, *final));
  AddFinalDesignRows(study, *layout, *final, data);
  return absl::OkStatus();
}

}  // namespace mbopt::client
