#include "worker/external/scene_analyzer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>
#include <variant>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "worker/external/runner.h"

namespace mbopt::external {
namespace {

// How far outside the driver's time span a grid instant may lie and still be
// taken as its end, relative to the span: drivers print their times, and a
// printed 0.30000000000000004 may come back as 0.3.
constexpr double kTimeSpanSlack = 1e-9;

template <typename Map>
std::string NamesOf(const Map& map) {
  if (map.empty()) return "none";
  std::vector<std::string> names;
  for (const auto& entry : map) names.push_back("\"" + entry.first + "\"");
  return absl::StrJoin(names, ", ");
}

// A label safe in a file name: anything else becomes '_', and at most 60
// characters (the driver's name and a counter follow it).
std::string SafeLabel(const std::string& label) {
  std::string out;
  for (const char c : label) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '-' || c == '.';
    out.push_back(ok ? c : '-');
  }
  if (out.size() > 60) out.resize(60);
  if (out.empty() || out[0] == '.') out.insert(out.begin(), 'a');
  return out;
}

absl::StatusOr<std::vector<double>> SeriesOnGrid(const std::string& output, const std::vector<double>& series,
                                                 const std::vector<double>& time_s,
                                                 const std::vector<double>& instants_s,
                                                 const std::string& results_file) {
  const std::string where = absl::StrCat(results_file, ": series \"", output, "\"");
  if (time_s.empty()) {
    if (series.size() != instants_s.size()) {
      return absl::InvalidArgumentError(absl::StrCat(
          where, " has ", series.size(), " numbers and the results give no \"time\": expected one number per "
          "instant of the scene's time grid (", instants_s.size(), "), or a \"time\" array to interpolate on"));
    }
    return series;
  }
  for (size_t i = 1; i < time_s.size(); ++i) {
    if (!(time_s[i] > time_s[i - 1])) {
      return absl::InvalidArgumentError(absl::StrCat(results_file, ": time[", i, "] = ", time_s[i],
                                                     " does not increase (time[", i - 1, "] = ", time_s[i - 1], ")"));
    }
  }
  const double first = time_s.front(), last = time_s.back();
  const double slack = kTimeSpanSlack * std::max(std::abs(last - first), std::abs(last));
  std::vector<double> out;
  out.reserve(instants_s.size());
  for (const double t : instants_s) {
    if (t < first - slack || t > last + slack) {
      return absl::InvalidArgumentError(absl::StrCat(where, ": the driver's time runs from ", first, " s to ", last,
                                                     " s, and the scene's time grid needs ", t, " s"));
    }
    if (time_s.size() == 1 || t <= first) {
      out.push_back(series.front());
      continue;
    }
    if (t >= last) {
      out.push_back(series.back());
      continue;
    }
    const size_t hi = static_cast<size_t>(std::upper_bound(time_s.begin(), time_s.end(), t) - time_s.begin());
    const size_t lo = hi - 1;
    const double w = (t - time_s[lo]) / (time_s[hi] - time_s[lo]);
    out.push_back(series[lo] + w * (series[hi] - series[lo]));
  }
  return out;
}

}  // namespace

const DriverDeclaration* FindDriver(const std::vector<DriverDeclaration>& drivers, const std::string& name) {
  for (const DriverDeclaration& driver : drivers) {
    if (driver.name == name) return &driver;
  }
  return nullptr;
}

absl::StatusOr<std::map<std::string, double>> DriverParameterValues(const DriverDeclaration& driver,
                                                                    const spec::ExternalModel& model,
                                                                    const std::vector<double>& parameter_values_si) {
  std::map<std::string, double> values;
  for (size_t i = 0; i < model.inputs.size(); ++i) {
    const spec::ExternalInput& input = model.inputs[i];
    if (std::find(driver.parameters.begin(), driver.parameters.end(), input.name) == driver.parameters.end()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "external.inputs[", i, "].name: driver \"", driver.name, "\" has no parameter \"", input.name,
          "\"; it declares: ", driver.parameters.empty() ? "none" : "\"" + absl::StrJoin(driver.parameters, "\", \"") + "\""));
    }
    values[input.name] = input.value.Resolve(parameter_values_si);
  }
  for (const std::string& parameter : driver.parameters) {
    if (values.count(parameter) == 0) {
      return absl::InvalidArgumentError(absl::StrCat("external.inputs: driver \"", driver.name, "\" takes parameter \"",
                                                     parameter, "\" and no input gives it a value"));
    }
  }
  return values;
}

absl::StatusOr<std::vector<spec::OutputValues>> OutputsFromResults(const spec::Scene& scene,
                                                                    const ExternalResults& results,
                                                                    const std::string& results_file) {
  const std::vector<double> instants_s = scene.time_grid.Instants();
  std::vector<spec::OutputValues> outputs;
  for (const spec::Output& output : scene.outputs) {
    const auto* wanted = std::get_if<spec::ExternalResultOutput>(&output.kind);
    if (wanted == nullptr) {
      return absl::InvalidArgumentError(
          absl::StrCat("output \"", output.name, "\" is not an external_value or external_series output"));
    }
    spec::OutputValues values;
    values.name = output.name;
    values.series_labels = {output.name};
    if (!wanted->series) {
      auto it = results.values.find(wanted->name);
      if (it == results.values.end()) {
        return absl::InvalidArgumentError(absl::StrCat(results_file, ": no value \"", wanted->name, "\" (output \"",
                                                       output.name, "\"); the file's values: ",
                                                       NamesOf(results.values)));
      }
      values.series = {{it->second}};
    } else {
      auto it = results.series.find(wanted->name);
      if (it == results.series.end()) {
        return absl::InvalidArgumentError(absl::StrCat(results_file, ": no series \"", wanted->name, "\" (output \"",
                                                       output.name, "\"); the file's series: ",
                                                       NamesOf(results.series)));
      }
      if (it->second.empty()) {
        return absl::InvalidArgumentError(
            absl::StrCat(results_file, ": series \"", wanted->name, "\" is empty (output \"", output.name, "\")"));
      }
      absl::StatusOr<std::vector<double>> on_grid =
          SeriesOnGrid(wanted->name, it->second, results.time_s, instants_s, results_file);
      if (!on_grid.ok()) return on_grid.status();
      values.series = {*std::move(on_grid)};
    }
    outputs.push_back(std::move(values));
  }
  return outputs;
}

absl::StatusOr<std::vector<std::vector<std::vector<double>>>> OutputDerivativesFromResults(
    const spec::Scene& scene, const ExternalResults& results, const std::vector<double>& parameter_values_si,
    const std::vector<int>& parameters, const std::string& results_file) {
  const auto* model = std::get_if<spec::ExternalModel>(&scene.model);
  if (model == nullptr) return absl::InvalidArgumentError("not an external scene");
  // input_partials[i][k] = d input i / d scene parameter parameters[k].
  std::vector<std::vector<double>> input_partials(model->inputs.size(), std::vector<double>(parameters.size(), 0.0));
  for (size_t i = 0; i < model->inputs.size(); ++i) {
    const spec::Number& value = model->inputs[i].value;
    if (value.expression != nullptr) {
      std::vector<double> partials;
      value.expression->EvaluateWithPartials(parameter_values_si, &partials);
      const std::vector<int>& read = value.expression->parameters();
      for (size_t r = 0; r < read.size(); ++r) {
        for (size_t k = 0; k < parameters.size(); ++k) {
          if (parameters[k] == read[r]) input_partials[i][k] += partials[r];
        }
      }
    } else {
      for (size_t k = 0; k < parameters.size(); ++k) {
        if (value.param >= 0 && parameters[k] == value.param) input_partials[i][k] = 1.0;
      }
    }
  }
  auto depends = [&](size_t i) {
    return std::any_of(input_partials[i].begin(), input_partials[i].end(), [](double d) { return d != 0.0; });
  };
  auto missing = [&](const char* kind, const std::string& name, const std::string& output,
                     const std::string& parameter, const std::string& given) {
    return absl::InvalidArgumentError(absl::StrCat(
        results_file, ": no gradient of ", kind, " \"", name, "\" (output \"", output,
        "\") with respect to parameter \"", parameter,
        "\": the study asks for simulator sensitivities (SENSITIVITY_METHOD_SIMULATOR), so the driver must write "
        "them (docs/external.md, \"Gradients\"); the file's gradients of it: ", given));
  };
  const std::vector<double> instants_s = scene.time_grid.Instants();
  std::vector<std::vector<std::vector<double>>> derivatives(parameters.size());
  for (const spec::Output& output : scene.outputs) {
    const auto* wanted = std::get_if<spec::ExternalResultOutput>(&output.kind);
    if (wanted == nullptr) {
      return absl::InvalidArgumentError(
          absl::StrCat("output \"", output.name, "\" is not an external_value or external_series output"));
    }
    const size_t length = wanted->series ? instants_s.size() : 1;
    std::vector<std::vector<double>> of_output(parameters.size(), std::vector<double>(length, 0.0));
    for (size_t i = 0; i < model->inputs.size(); ++i) {
      if (!depends(i)) continue;
      const std::string& parameter = model->inputs[i].name;
      std::vector<double> d_output_d_input;
      if (!wanted->series) {
        const auto of_value = results.value_gradients.find(wanted->name);
        const double* found = nullptr;
        if (of_value != results.value_gradients.end()) {
          const auto it = of_value->second.find(parameter);
          if (it != of_value->second.end()) found = &it->second;
        }
        if (found == nullptr) {
          return missing("value", wanted->name, output.name, parameter,
                         of_value == results.value_gradients.end() ? "none" : NamesOf(of_value->second));
        }
        d_output_d_input = {*found};
      } else {
        const auto of_series = results.series_gradients.find(wanted->name);
        const std::vector<double>* found = nullptr;
        if (of_series != results.series_gradients.end()) {
          const auto it = of_series->second.find(parameter);
          if (it != of_series->second.end()) found = &it->second;
        }
        if (found == nullptr) {
          return missing("series", wanted->name, output.name, parameter,
                         of_series == results.series_gradients.end() ? "none" : NamesOf(of_series->second));
        }
        // Linear interpolation weights do not depend on the values: the
        // derivative goes onto the grid as the series does.
        absl::StatusOr<std::vector<double>> on_grid =
            SeriesOnGrid(absl::StrCat("gradient of ", wanted->name, " with respect to ", parameter), *found,
                         results.time_s, instants_s, results_file);
        if (!on_grid.ok()) return on_grid.status();
        d_output_d_input = *std::move(on_grid);
      }
      for (size_t k = 0; k < parameters.size(); ++k) {
        const double chain = input_partials[i][k];
        if (chain == 0.0) continue;
        for (size_t t = 0; t < length; ++t) of_output[k][t] += chain * d_output_d_input[t];
      }
    }
    for (size_t k = 0; k < parameters.size(); ++k) derivatives[k].push_back(std::move(of_output[k]));
  }
  return derivatives;
}

ExternalSceneAnalyzer::ExternalSceneAnalyzer(const ExternalWorkerSettings& settings, const std::string& label)
    : settings_(settings), label_(SafeLabel(label)) {}

spec::AnalysisReport ExternalSceneAnalyzer::AnalyzeExternal(const spec::Scene& scene,
                                                            const std::vector<double>& parameter_values_si) const {
  return Analyze(scene, parameter_values_si, {}, nullptr);
}

spec::AnalysisReport ExternalSceneAnalyzer::AnalyzeExternalWithSensitivities(
    const spec::Scene& scene, const std::vector<double>& parameter_values_si, const std::vector<int>& parameters,
    std::vector<std::vector<std::vector<double>>>* output_derivatives) const {
  return Analyze(scene, parameter_values_si, parameters, output_derivatives);
}

spec::AnalysisReport ExternalSceneAnalyzer::Analyze(
    const spec::Scene& scene, const std::vector<double>& parameter_values_si, const std::vector<int>& parameters,
    std::vector<std::vector<std::vector<double>>>* output_derivatives) const {
  spec::AnalysisReport report;
  report.formulation = spec::Formulation::kExternal;
  report.times_s = scene.time_grid.Instants();
  const auto* model = std::get_if<spec::ExternalModel>(&scene.model);
  if (model == nullptr) {
    report.Fail(spec::FailureKind::kInvalidModel, "not an external scene");
    return report;
  }
  const DriverDeclaration* driver = FindDriver(settings_.drivers, model->driver);
  if (driver == nullptr) {
    std::vector<std::string> names;
    for (const DriverDeclaration& d : settings_.drivers) names.push_back(d.name);
    // Not the design's fault: another worker may declare it.
    report.Fail(spec::FailureKind::kService,
                absl::StrCat("this worker declares no driver \"", model->driver, "\"; it declares: ",
                             names.empty() ? "none" : "\"" + absl::StrJoin(names, "\", \"") + "\""));
    return report;
  }
  absl::StatusOr<std::map<std::string, double>> values =
      DriverParameterValues(*driver, *model, parameter_values_si);
  if (!values.ok()) {
    report.Fail(spec::FailureKind::kInvalidModel, absl::StrCat(scene.source_file, ": ", values.status().message()));
    return report;
  }
  RunOptions options;
  options.analysis_id = absl::StrCat(label_, "-", settings_.next_analysis.fetch_add(1));
  options.work_directory = settings_.work_directory;
  options.keep_run_folder = settings_.keep_run_folders;
  options.kill_grace_s = settings_.kill_grace_s;
  absl::StatusOr<ExternalOutcome> outcome = RunExternalAnalysis(*driver, *values, options);
  if (!outcome.ok()) {
    // The machine's or the declaration's fault (a folder that cannot be
    // made, a command that cannot start), never the design's.
    report.Fail(spec::FailureKind::kService,
                absl::StrCat("driver \"", driver->name, "\": ", outcome.status().message()));
    return report;
  }
  report.counters.wall_seconds = outcome->wall_seconds;
  if (!outcome->failure.ok()) {
    report.Fail(outcome->failure.kind, outcome->failure.reason);
    return report;
  }
  absl::StatusOr<std::vector<spec::OutputValues>> outputs =
      OutputsFromResults(scene, outcome->results, driver->results_file);
  if (!outputs.ok()) {
    report.Fail(spec::FailureKind::kInvalidModel,
                absl::StrCat("driver \"", driver->name, "\": ", outputs.status().message()));
    return report;
  }
  if (output_derivatives != nullptr) {
    absl::StatusOr<std::vector<std::vector<std::vector<double>>>> derivatives = OutputDerivativesFromResults(
        scene, outcome->results, parameter_values_si, parameters, driver->results_file);
    if (!derivatives.ok()) {
      report.Fail(spec::FailureKind::kInvalidModel,
                  absl::StrCat("driver \"", driver->name, "\": ", derivatives.status().message()));
      return report;
    }
    *output_derivatives = *std::move(derivatives);
  }
  report.outputs = *std::move(outputs);
  return report;
}

}  // namespace mbopt::external
