#include "worker/main/eval_command.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <ostream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "mbopt/v1/series.pb.h"
#include "common/monotonic_clock.h"
#include "spec/io/study_io.h"
#include "spec/layout.h"
#include "worker/budget/analysis_budget.h"
#include "worker/engine/analysis.h"
#include "worker/engine/study_values.h"
#include "worker/external/worker_settings.h"

namespace mbopt::worker {
namespace {

const char kUsage[] =
    "usage: mbopt-worker eval STUDY [--set NAME=VALUE ...] [--json] [--series-out FILE]\n"
    "                          [--drivers FILE [--work-dir DIR] [--keep-runs]]\n"
    "  Runs one analysis of STUDY (a .study.textproto) at its initial design and\n"
    "  prints the objective, the worst constraint row, per-output summaries,\n"
    "  the formulation and the counters.\n"
    "  --set NAME=VALUE  NAME is a design variable (VALUE scaled, as in the study's\n"
    "                    bounds) or a scene parameter (VALUE in the parameter's own\n"
    "                    unit); repeatable\n"
    "  --json            print one JSON object instead of text\n"
    "  --series-out FILE also write every output (per load case) and response\n"
    "                    series, SI, to FILE (binary mbopt.v1.AnalysisSeries,\n"
    "                    proto/mbopt/v1/series.proto): what `mbopt report` plots\n"
    "  --drivers FILE, --work-dir DIR, --keep-runs  analysis drivers for an external\n"
    "                    scene, as for `mbopt-worker serve`\n"
    "  exit status: 0 ok, 1 analysis failed, 2 bad input\n";

std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += absl::StrFormat("\\u%04x", static_cast<int>(c));
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string JsonNumber(double v) { return std::isfinite(v) ? absl::StrFormat("%.17g", v) : "null"; }

// Every signal's series (outputs per load case, then responses) in a binary
// mbopt.v1.AnalysisSeries; a failed analysis writes its reason instead.
absl::Status WriteSeries(const spec::Study& study, const spec::StudyLayout& layout,
                         const spec::AnalysisReport& report, const std::vector<double>& parameters_si,
                         const std::string& path) {
  v1::AnalysisSeries message;
  message.mutable_times_s()->Assign(report.times_s.begin(), report.times_s.end());
  engine::StudySignals signals;
  absl::Status built = report.ok()
                           ? engine::BuildStudySignals(study, layout, report, parameters_si, &signals)
                           : absl::FailedPreconditionError(report.failure.reason);
  if (!built.ok()) {
    message.set_failure(std::string(built.message()));
  } else {
    for (size_t k = 0; k < signals.signals.size(); ++k) {
      v1::SignalSeries* signal = message.add_signals();
      signal->set_name(study.SignalName(static_cast<int>(k)));
      const spec::OutputShape& shape = layout.outputs[k];
      for (size_t s = 0; s < signals.signals[k]->size(); ++s) {
        signal->add_labels(s < shape.series_labels.size() ? shape.series_labels[s] : absl::StrCat(s));
        const std::vector<double>& values = (*signals.signals[k])[s];
        signal->add_series()->mutable_values_si()->Assign(values.begin(), values.end());
      }
    }
  }
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  if (!file || !message.SerializeToOstream(&file)) return absl::InvalidArgumentError("cannot write " + path);
  file.close();
  if (!file) return absl::InvalidArgumentError("cannot write " + path);
  return absl::OkStatus();
}

struct SeriesSummary {
  std::string label;
  double min = 0, max = 0, t_min = 0, t_max = 0;
};

SeriesSummary Summarize(const std::string& label, const std::vector<double>& values,
                        const std::vector<double>& times) {
  SeriesSummary s;
  s.label = label;
  if (values.empty()) return s;
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  s.min = *lo;
  s.max = *hi;
  const auto at = [&](auto it) {
    const size_t i = static_cast<size_t>(it - values.begin());
    return i < times.size() && values.size() == times.size() ? times[i] : 0.0;
  };
  s.t_min = at(lo);
  s.t_max = at(hi);
  return s;
}

}  // namespace

absl::Status ApplyDesignSet(const spec::Study& study, const std::string& assignment,
                      std::vector<double>* x,
                      std::vector<std::pair<int, double>>* parameter_overrides) {
  const size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("--set expects NAME=VALUE, got \"", assignment, "\""));
  }
  const std::string name = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end == nullptr || *end != '\0' || !std::isfinite(value)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--set ", name, ": \"", text, "\" is not a finite number"));
  }
  for (size_t k = 0; k < study.variables.size(); ++k) {
    if (study.variables[k].name == name) {
      (*x)[k] = value;
      return absl::OkStatus();
    }
  }
  const int p = study.scene.FindParameter(name);
  if (p < 0) {
    std::vector<std::string> names;
    for (const auto& v : study.variables) names.push_back(v.name);
    return absl::InvalidArgumentError(
        absl::StrCat("--set: \"", name, "\" is neither a design variable (",
                     absl::StrJoin(names, ", "), ") nor a scene parameter"));
  }
  if (study.scene.ParameterExpression(p) != nullptr) {
    // Nothing reads its own value: every use computes it from those it reads.
    return absl::InvalidArgumentError(absl::StrCat("--set: parameter \"", name,
                                                   "\" is an expression of other parameters (`expr` in the scene); "
                                                   "set those it reads"));
  }
  for (size_t k = 0; k < study.variables.size(); ++k) {
    if (study.variables[k].parameter == p) {
      // A bound parameter moves its variable, so the design stays consistent.
      (*x)[k] = value / study.variables[k].scale;
      return absl::OkStatus();
    }
  }
  parameter_overrides->emplace_back(p, value * study.scene.parameters[p].si_per_unit);
  return absl::OkStatus();
}

const char* EvalUsage() { return kUsage; }

int RunEval(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  std::string study_path;
  std::vector<std::string> sets;
  std::string series_out;
  bool json = false;
  external::ExternalOptions external_options;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    bool takes_value = false;
    if (external::IsExternalOption(a, &takes_value)) {
      if (takes_value && i + 1 >= args.size()) {
        err << "mbopt-worker eval: " << a << " needs a value\n" << kUsage;
        return kExitBadInput;
      }
      if (!external::SetExternalOption(a, takes_value ? args[++i] : "", &external_options)) {
        err << "mbopt-worker eval: bad value for " << a << "\n" << kUsage;
        return kExitBadInput;
      }
    } else if (a == "--json") {
      json = true;
    } else if (a == "--set") {
      if (i + 1 >= args.size()) {
        err << "mbopt-worker eval: --set needs NAME=VALUE\n" << kUsage;
        return kExitBadInput;
      }
      sets.push_back(args[++i]);
    } else if (a.rfind("--set=", 0) == 0) {
      sets.push_back(a.substr(6));
    } else if (a == "--series-out") {
      if (i + 1 >= args.size()) {
        err << "mbopt-worker eval: --series-out needs a file\n" << kUsage;
        return kExitBadInput;
      }
      series_out = args[++i];
    } else if (a == "--help" || a == "-h") {
      out << kUsage;
      return kExitOk;
    } else if (!a.empty() && a[0] == '-') {
      err << "mbopt-worker eval: unknown option \"" << a << "\"\n" << kUsage;
      return kExitBadInput;
    } else if (study_path.empty()) {
      study_path = a;
    } else {
      err << "mbopt-worker eval: more than one study file given\n" << kUsage;
      return kExitBadInput;
    }
  }
  if (study_path.empty()) {
    err << "mbopt-worker eval: no study file given\n" << kUsage;
    return kExitBadInput;
  }

  absl::StatusOr<std::unique_ptr<external::ExternalWorkerSettings>> external_settings =
      external::LoadExternalSettings(external_options);
  if (!external_settings.ok()) {
    err << "mbopt-worker eval: " << external_settings.status().message() << "\n";
    return kExitBadInput;
  }
  absl::StatusOr<spec::Study> loaded = spec::io::LoadStudyFile(study_path);
  if (!loaded.ok()) {
    err << loaded.status().message() << "\n";
    return kExitBadInput;
  }
  const spec::Study& study = *loaded;
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(study);
  if (!layout.ok()) {
    err << layout.status().message() << "\n";
    return kExitBadInput;
  }

  std::vector<double> x;
  for (const auto& v : study.variables) x.push_back(v.initial);
  std::vector<std::pair<int, double>> overrides;
  for (const std::string& s : sets) {
    if (absl::Status st = ApplyDesignSet(study, s, &x, &overrides); !st.ok()) {
      err << "mbopt-worker eval: " << st.message() << "\n";
      return kExitBadInput;
    }
  }
  std::vector<double> parameters = study.ParameterValuesAt(x);
  for (const auto& [p, value] : overrides) parameters[static_cast<size_t>(p)] = value;
  std::vector<std::string> outside;
  for (size_t k = 0; k < x.size(); ++k) {
    const auto& v = study.variables[k];
    if (x[k] < v.lower || x[k] > v.upper) {
      outside.push_back(
          absl::StrFormat("%s = %g outside [%g, %g]", v.name, x[k], v.lower, v.upper));
    }
  }

  std::unique_ptr<external::ExternalSceneAnalyzer> analyzer;
  if (*external_settings != nullptr) {
    analyzer = std::make_unique<external::ExternalSceneAnalyzer>(**external_settings, "eval");
  }
  // On this process' clock: the scene's time limit applies as on a worker.
  const spec::AnalysisReport report =
      engine::AnalyzeCases(study, parameters, analyzer.get(), budget::AnalysisBudget(&MonotonicSeconds, nullptr));
  external::RemoveDefaultWorkDirectoryIfEmpty(external_options, external_settings->get());
  const bool ok = report.ok();
  if (!series_out.empty()) {
    if (absl::Status written = WriteSeries(study, *layout, report, parameters, series_out); !written.ok()) {
      err << "mbopt-worker eval: " << written.message() << "\n";
      return kExitBadInput;
    }
  }
  absl::StatusOr<spec::StudyValues> values =
      ok ? engine::ComputeStudyValues(study, *layout, report, parameters)
         : absl::StatusOr<spec::StudyValues>(absl::FailedPreconditionError(report.failure.reason));
  if (ok && !values.ok()) {
    err << "mbopt-worker eval: " << values.status().message() << "\n";
    return kExitAnalysisFailed;
  }
  const std::string objective_unit = spec::ReportedObjectiveUnit(study);

  // Every output (per load case), then every response: what a user checks
  // their response expressions against.
  std::vector<std::vector<SeriesSummary>> summaries;
  std::vector<std::string> summary_names;
  for (const auto& o : report.outputs) {
    std::vector<SeriesSummary> per_series;
    for (size_t s = 0; s < o.series.size(); ++s) {
      per_series.push_back(
          Summarize(s < o.series_labels.size() ? o.series_labels[s] : absl::StrCat(s), o.series[s],
                    report.times_s));
    }
    summaries.push_back(std::move(per_series));
    summary_names.push_back(o.name);
  }
  engine::StudySignals signals;
  if (ok && !study.responses.empty() &&
      engine::BuildStudySignals(study, *layout, report, parameters, &signals).ok()) {
    for (int k = study.num_case_signals(); k < study.num_signals(); ++k) {
      const spec::OutputShape& shape = layout->outputs[static_cast<size_t>(k)];
      std::vector<SeriesSummary> per_series;
      for (size_t s = 0; s < signals.signals[static_cast<size_t>(k)]->size(); ++s) {
        per_series.push_back(Summarize(s < shape.series_labels.size() ? shape.series_labels[s] : absl::StrCat(s),
                                       (*signals.signals[static_cast<size_t>(k)])[s], report.times_s));
      }
      summaries.push_back(std::move(per_series));
      summary_names.push_back(study.SignalName(k));
    }
  }
  const auto& c = report.counters;

  if (json) {
    out << "{";
    out << "\"study\": " << JsonString(study.name);
    out << ", \"status\": " << JsonString(ok ? "ok" : "failed");
    if (!ok) out << ", \"failure_reason\": " << JsonString(report.failure.reason);
    out << ", \"formulation\": " << JsonString(spec::FormulationName(report.formulation));
    out << ", \"design\": {";
    for (size_t k = 0; k < x.size(); ++k) {
      out << (k ? ", " : "") << JsonString(study.variables[k].name) << ": " << JsonNumber(x[k]);
    }
    out << "}";
    if (ok) {
      out << ", \"objective\": " << JsonNumber(study.objective.ReportedSign() * values->objective);
      out << ", \"objective_unit\": " << JsonString(objective_unit);
      out << ", \"objective_terms\": " << values->objective_terms.size();
      out << ", \"max_violation\": " << JsonNumber(values->max_violation);
      out << ", \"constraint_rows\": " << layout->rows.size();
      if (values->worst_row >= 0) {
        const spec::ConstraintRow& row = layout->rows[static_cast<size_t>(values->worst_row)];
        out << ", \"worst_constraint\": {\"row\": " << values->worst_row
            << ", \"name\": " << JsonString(row.name)
            << ", \"value_si\": " << JsonNumber(values->constraint_values[values->worst_row])
            << ", \"limit_si\": " << JsonNumber(row.limit_si)
            << ", \"time_s\": " << JsonNumber(row.time_s) << "}";
      } else {
        out << ", \"worst_constraint\": null";
      }
    } else {
      out << ", \"objective\": null, \"max_violation\": null, \"worst_constraint\": null";
    }
    out << ", \"outputs\": [";
    for (size_t o = 0; o < summaries.size(); ++o) {
      out << (o ? ", " : "") << "{\"name\": " << JsonString(summary_names[o])
          << ", \"series\": [";
      for (size_t s = 0; s < summaries[o].size(); ++s) {
        const SeriesSummary& m = summaries[o][s];
        out << (s ? ", " : "") << "{\"label\": " << JsonString(m.label)
            << ", \"min_si\": " << JsonNumber(m.min) << ", \"t_min_s\": " << JsonNumber(m.t_min)
            << ", \"max_si\": " << JsonNumber(m.max) << ", \"t_max_s\": " << JsonNumber(m.t_max)
            << "}";
      }
      out << "]}";
    }
    out << "]";
    out << ", \"counters\": {\"time_steps\": " << c.time_steps
        << ", \"rhs_evaluations\": " << c.rhs_evaluations
        << ", \"jacobian_evaluations\": " << c.jacobian_evaluations
        << ", \"newton_iterations\": " << c.newton_iterations
        << ", \"position_solves\": " << c.position_solves
        << ", \"wall_seconds\": " << JsonNumber(c.wall_seconds) << "}";
    if (!outside.empty()) {
      out << ", \"warnings\": [";
      for (size_t i = 0; i < outside.size(); ++i) out << (i ? ", " : "") << JsonString(outside[i]);
      out << "]";
    }
    out << "}\n";
    return ok ? kExitOk : kExitAnalysisFailed;
  }

  out << "study        " << study.name << " (" << study.source_file << ")\n";
  std::vector<std::string> design;
  for (size_t k = 0; k < x.size(); ++k) {
    design.push_back(absl::StrFormat("%s=%g", study.variables[k].name, x[k]));
  }
  out << "design       " << absl::StrJoin(design, " ") << "\n";
  for (const std::string& w : outside) out << "warning      " << w << "\n";
  out << "formulation  " << spec::FormulationName(report.formulation) << "\n";
  if (!ok) {
    out << "status       FAILED: " << report.failure.reason << "\n";
  } else {
    out << "status       ok\n";
    out << absl::StrFormat("objective    %.6g %s (%d term%s)\n", study.objective.ReportedSign() * values->objective,
                           objective_unit,
                           values->objective_terms.size(),
                           values->objective_terms.size() == 1 ? "" : "s");
    if (values->worst_row >= 0) {
      const spec::ConstraintRow& row = layout->rows[static_cast<size_t>(values->worst_row)];
      out << absl::StrFormat(
          "worst row    %s: g = %.6g, limit %.6g (SI), normalized %+.4g (%s) of %d rows\n",
          row.name, values->constraint_values[values->worst_row], row.limit_si,
          values->max_violation, values->max_violation > 0 ? "violated" : "satisfied",
          layout->rows.size());
    } else {
      out << "worst row    (no constraints)\n";
    }
  }
  out << "outputs      (SI; min and max over the grid; responses after the outputs)\n";
  for (size_t o = 0; o < summaries.size(); ++o) {
    for (const SeriesSummary& m : summaries[o]) {
      const std::string label = summaries[o].size() > 1
                                    ? absl::StrCat(summary_names[o], "[", m.label, "]")
                                    : summary_names[o];
      out << absl::StrFormat("  %-24s min %-13.6g at t=%-8.4g max %-13.6g at t=%.4g\n", label,
                             m.min, m.t_min, m.max, m.t_max);
    }
  }
  out << absl::StrFormat(
      "counters     steps %d, rhs %d, jacobians %d, newton %d, position solves %d, wall %.3f ms\n",
      c.time_steps, c.rhs_evaluations, c.jacobian_evaluations, c.newton_iterations,
      c.position_solves, c.wall_seconds * 1e3);
  return ok ? kExitOk : kExitAnalysisFailed;
}

}  // namespace mbopt::worker
