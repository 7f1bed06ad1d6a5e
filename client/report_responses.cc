#include "client/report_responses.h"

#include <google/protobuf/text_format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
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

// One signal's plot: the series that comes closest to its limit at the
// final design (the largest |value| without limits), in `unit`.
report::ResponsePlot SignalPlot(const v1::AnalysisSeries& initial, const v1::AnalysisSeries& final, int signal,
                                double si_per_unit, const std::string& unit, const std::string& title) {
  report::ResponsePlot plot;
  plot.title = title;
  plot.unit = unit;
  const v1::SignalSeries& a = initial.signals(signal);
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

}  // namespace

void AddResponsePlots(const v1::GetJobResponse& job, report::ReportData* data) {
  const v1::JobSummary& summary = job.summary();
  absl::StatusOr<spec::Study> loaded = spec::io::StudyFromProto(job.study(), "the job's study");
  if (!loaded.ok()) {
    data->responses_note = "The job's study could not be read: " + std::string(loaded.status().message());
    return;
  }
  const spec::Study& study = *loaded;
  if (job.cycles_size() == 0 || summary.design_size() != static_cast<int>(study.variables.size())) {
    data->responses_note = "The job has no analysed design yet.";
    return;
  }
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(study);
  absl::StatusOr<std::string> worker = FindMboptBinary("mbopt-worker", "MBOPT_WORKER_BIN", "worker/main");
  if (!layout.ok() || !worker.ok()) {
    data->responses_note = "The responses cannot be analysed here: " +
                           std::string((!layout.ok() ? layout.status() : worker.status()).message());
    return;
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
      return;
    }
  }
  if (initial->signals_size() != study.num_signals() || final->signals_size() != study.num_signals()) {
    data->responses_note = "The responses are not shown: the analyses returned another number of signals.";
    return;
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
    if (!whole) {
      bound = absl::StrFormat("%s %g%s", c.reduction == spec::Reduction::kMin ? ">=" : "<=", c.limit, unit);
      limits.push_back({c.limit, c.reduction == spec::Reduction::kMin ? "lower limit" : "limit"});
      if (c.reduction == spec::Reduction::kMaxAbs) limits.push_back({-c.limit, "-limit"});
    } else {
      if (c.lower) bound += absl::StrFormat(">= %g%s", *c.lower, unit);
      if (c.upper) bound += absl::StrFormat("%s<= %g%s", bound.empty() ? "" : ", ", *c.upper, unit);
      // A bound on the final value is a level on the curve; one on an RMS,
      // mean, integral or range is not, and is stated in the note instead.
      if (c.reduction == spec::Reduction::kFinal) {
        if (c.lower) limits.push_back({*c.lower, "lower"});
        if (c.upper) limits.push_back({*c.upper, "upper"});
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
}

}  // namespace mbopt::client
