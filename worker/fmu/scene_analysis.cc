#include "worker/fmu/scene_analysis.h"

#include <cmath>
#include <filesystem>
#include <optional>
#include <string>
#include <variant>

#include "absl/strings/str_cat.h"
#include "worker/fmu/archive_cache.h"
#include "worker/fmu/fmu.h"
#include "worker/fmu/sensitivities.h"
#include "worker/fmu/simulation.h"

namespace mbopt::fmu {
namespace {

spec::FailureKind KindOf(RunOutcome outcome) {
  switch (outcome) {
    case RunOutcome::kOk:
    case RunOutcome::kModelError: return spec::FailureKind::kInvalidModel;
    case RunOutcome::kIntegratorFailure: return spec::FailureKind::kIntegrator;
    case RunOutcome::kTerminated: return spec::FailureKind::kModelValidity;
    case RunOutcome::kTimeLimit: return spec::FailureKind::kTimeLimit;
    case RunOutcome::kCancelled: return spec::FailureKind::kCancelled;
  }
  return spec::FailureKind::kInvalidModel;
}

// The scene's FMU opened and its run described, or null with `report`
// failed saying why.
struct PreparedRun {
  std::optional<Fmu> fmu;
  RunOptions options;
};

PreparedRun Prepare(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                    const budget::AnalysisBudget* budget, spec::AnalysisReport* report) {
  PreparedRun prepared;
  report->formulation = spec::Formulation::kDynamic;
  report->times_s = scene.time_grid.Instants();
  const auto* model = std::get_if<spec::FmuModel>(&scene.model);
  if (model == nullptr) {
    report->Fail(spec::FailureKind::kInvalidModel, "not an FMU scene");
    return prepared;
  }
  RunOptions& options = prepared.options;
  options.start_time_s = 0.0;
  for (const spec::FmuParameterBinding& binding : model->parameters) {
    options.parameters.emplace_back(binding.variable, binding.value.Resolve(parameter_values_si));
  }
  for (const spec::Output& output : scene.outputs) {
    const auto* variable = std::get_if<spec::FmuVariableOutput>(&output.kind);
    if (variable == nullptr) {
      report->Fail(spec::FailureKind::kInvalidModel, absl::StrCat("output \"", output.name, "\" is no FMU variable"));
      return prepared;
    }
    options.outputs.push_back(variable->variable);
  }
  options.output_times_s = report->times_s;
  options.relative_tolerance = scene.integrator.relative_tolerance;
  options.absolute_tolerance = scene.integrator.absolute_tolerance;
  options.max_steps = scene.integrator.max_steps;
  options.budget = budget;
  if (model->communication_step_s > 0.0) options.communication_step_s = model->communication_step_s;

  const Interface interface = model->co_simulation ? Interface::kCoSimulation : Interface::kModelExchange;
  absl::StatusOr<Fmu> fmu = absl::UnknownError("not opened");
  if (model->archive != nullptr) {
    // The study carries the FMU: unpacked once per content on this machine.
    absl::StatusOr<std::filesystem::path> folder =
        UnpackedArchiveFolder(*model->archive, model->archive_sha256, model->path);
    fmu = folder.ok() ? Fmu::OpenUnpacked(model->path, *folder, interface) : absl::StatusOr<Fmu>(folder.status());
  } else {
    fmu = Fmu::Open(model->path, interface);
  }
  if (!fmu.ok()) {
    report->Fail(spec::FailureKind::kInvalidModel, std::string(fmu.status().message()));
    return prepared;
  }
  prepared.fmu.emplace(*std::move(fmu));
  return prepared;
}

// The run's values as the report's outputs; false (and `report` failed)
// when the run failed or a value is not finite.
bool Report(const spec::Scene& scene, const RunOptions& options, RunResult result, spec::AnalysisReport* report) {
  report->counters.time_steps = result.integrator_steps;
  if (result.outcome != RunOutcome::kOk) {
    report->Fail(KindOf(result.outcome), result.reason);
    return false;
  }
  for (std::size_t k = 0; k < scene.outputs.size(); ++k) {
    for (std::size_t i = 0; i < report->times_s.size(); ++i) {
      if (!std::isfinite(result.values[k][i])) {
        report->Fail(spec::FailureKind::kNonFiniteValue,
                     absl::StrCat("FMU variable \"", options.outputs[k], "\" (output \"", scene.outputs[k].name,
                                  "\") is ", result.values[k][i], " at t = ", report->times_s[i], " s"));
        return false;
      }
    }
    spec::OutputValues values;
    values.name = scene.outputs[k].name;
    values.series_labels = {scene.outputs[k].name};
    values.series = {std::move(result.values[k])};
    report->outputs.push_back(std::move(values));
  }
  return true;
}

// d binding / d scene parameter p for every binding and every p in
// `parameters`: [binding][k].
std::vector<std::vector<double>> BindingPartials(const spec::FmuModel& model,
                                                 const std::vector<double>& parameter_values_si,
                                                 const std::vector<int>& parameters) {
  std::vector<std::vector<double>> partials(model.parameters.size(), std::vector<double>(parameters.size(), 0.0));
  for (std::size_t b = 0; b < model.parameters.size(); ++b) {
    const spec::Number& value = model.parameters[b].value;
    if (value.expression != nullptr) {
      std::vector<double> by_read;
      value.expression->EvaluateWithPartials(parameter_values_si, &by_read);
      const std::vector<int>& read = value.expression->parameters();
      for (std::size_t k = 0; k < parameters.size(); ++k) {
        for (std::size_t r = 0; r < read.size(); ++r) {
          if (read[r] == parameters[k]) partials[b][k] = by_read[r];
        }
      }
    } else {
      for (std::size_t k = 0; k < parameters.size(); ++k) {
        if (value.param == parameters[k]) partials[b][k] = 1.0;
      }
    }
  }
  return partials;
}

// Indices of the bindings that depend on any of `parameters`.
std::vector<int> DifferentiatedBindings(const spec::FmuModel& model, const std::vector<int>& parameters) {
  std::vector<int> bindings;
  for (std::size_t b = 0; b < model.parameters.size(); ++b) {
    for (int p : parameters) {
      if (model.parameters[b].value.DependsOn(p)) {
        bindings.push_back(static_cast<int>(b));
        break;
      }
    }
  }
  return bindings;
}

}  // namespace

spec::AnalysisReport AnalyzeFmuScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                     const budget::AnalysisBudget* budget) {
  spec::AnalysisReport report;
  PreparedRun prepared = Prepare(scene, parameter_values_si, budget, &report);
  if (!prepared.fmu.has_value()) return report;
  auto result = Simulate(*prepared.fmu, prepared.options);
  if (!result.ok()) {
    report.Fail(spec::FailureKind::kInvalidModel, std::string(result.status().message()));
    return report;
  }
  Report(scene, prepared.options, *std::move(result), &report);
  return report;
}

std::string FmuSensitivitiesUnavailable(const spec::Scene& scene, const std::vector<int>& parameters) {
  const auto* model = std::get_if<spec::FmuModel>(&scene.model);
  if (model == nullptr) return "not an FMU scene";
  if (model->co_simulation) {
    return "a Co-Simulation FMU integrates itself, so it has no forward sensitivities (use its Model Exchange "
           "interface)";
  }
  auto fmu = Fmu::Open(model->path, Interface::kModelExchange);
  if (!fmu.ok()) return std::string(fmu.status().message());
  std::vector<std::string> names;
  for (int b : DifferentiatedBindings(*model, parameters)) names.push_back(model->parameters[b].variable);
  return SensitivitiesUnavailable(*fmu, names);
}

FmuSensitivityAnalysis AnalyzeFmuSceneWithSensitivities(const spec::Scene& scene,
                                                        const std::vector<double>& parameter_values_si,
                                                        const std::vector<int>& parameters,
                                                        const budget::AnalysisBudget* budget) {
  FmuSensitivityAnalysis out;
  PreparedRun prepared = Prepare(scene, parameter_values_si, budget, &out.report);
  if (!prepared.fmu.has_value()) return out;
  const auto& model = std::get<spec::FmuModel>(scene.model);
  const std::vector<int> bindings = DifferentiatedBindings(model, parameters);
  auto result = SimulateWithSensitivities(*prepared.fmu, prepared.options, bindings);
  if (!result.ok()) {
    out.report.Fail(spec::FailureKind::kInvalidModel, std::string(result.status().message()));
    return out;
  }
  out.unavailable = std::move(result->unavailable);
  const std::vector<std::vector<std::vector<double>>> by_binding = std::move(result->output_derivatives);
  if (!Report(scene, prepared.options, std::move(result->run), &out.report) || !out.unavailable.empty()) return out;
  // Chain rule: d output / d p_k = sum over bindings of d output / d binding
  // * d binding / d p_k.
  const std::vector<std::vector<double>> partials = BindingPartials(model, parameter_values_si, parameters);
  const std::size_t num_times = out.report.times_s.size();
  out.output_derivatives.assign(
      parameters.size(),
      std::vector<std::vector<double>>(scene.outputs.size(), std::vector<double>(num_times, 0.0)));
  for (std::size_t j = 0; j < bindings.size(); ++j) {
    for (std::size_t k = 0; k < parameters.size(); ++k) {
      const double partial = partials[bindings[j]][k];
      if (partial == 0.0) continue;
      for (std::size_t o = 0; o < scene.outputs.size(); ++o) {
        for (std::size_t i = 0; i < num_times; ++i) {
          out.output_derivatives[k][o][i] += by_binding[j][o][i] * partial;
        }
      }
    }
  }
  return out;
}

}  // namespace mbopt::fmu
