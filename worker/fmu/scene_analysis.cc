#include "worker/fmu/scene_analysis.h"

#include <cmath>
#include <filesystem>
#include <string>
#include <variant>

#include "absl/strings/str_cat.h"
#include "worker/fmu/archive_cache.h"
#include "worker/fmu/fmu.h"
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

}  // namespace

spec::AnalysisReport AnalyzeFmuScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                     const budget::AnalysisBudget* budget) {
  spec::AnalysisReport report;
  report.formulation = spec::Formulation::kDynamic;
  report.times_s = scene.time_grid.Instants();
  const auto* model = std::get_if<spec::FmuModel>(&scene.model);
  if (model == nullptr) {
    report.Fail(spec::FailureKind::kInvalidModel, "not an FMU scene");
    return report;
  }
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
    report.Fail(spec::FailureKind::kInvalidModel, std::string(fmu.status().message()));
    return report;
  }

  RunOptions options;
  options.start_time_s = 0.0;
  for (const spec::FmuParameterBinding& binding : model->parameters) {
    options.parameters.emplace_back(binding.variable, binding.value.Resolve(parameter_values_si));
  }
  for (const spec::Output& output : scene.outputs) {
    const auto* variable = std::get_if<spec::FmuVariableOutput>(&output.kind);
    if (variable == nullptr) {
      report.Fail(spec::FailureKind::kInvalidModel, absl::StrCat("output \"", output.name, "\" is no FMU variable"));
      return report;
    }
    options.outputs.push_back(variable->variable);
  }
  options.output_times_s = report.times_s;
  options.relative_tolerance = scene.integrator.relative_tolerance;
  options.absolute_tolerance = scene.integrator.absolute_tolerance;
  options.max_steps = scene.integrator.max_steps;
  options.budget = budget;
  if (model->communication_step_s > 0.0) options.communication_step_s = model->communication_step_s;

  auto result = Simulate(*fmu, options);
  if (!result.ok()) {
    report.Fail(spec::FailureKind::kInvalidModel, std::string(result.status().message()));
    return report;
  }
  report.counters.time_steps = result->integrator_steps;
  if (result->outcome != RunOutcome::kOk) {
    report.Fail(KindOf(result->outcome), result->reason);
    return report;
  }
  for (std::size_t k = 0; k < scene.outputs.size(); ++k) {
    for (std::size_t i = 0; i < report.times_s.size(); ++i) {
      if (!std::isfinite(result->values[k][i])) {
        report.Fail(spec::FailureKind::kNonFiniteValue,
                    absl::StrCat("FMU variable \"", options.outputs[k], "\" (output \"", scene.outputs[k].name,
                                 "\") is ", result->values[k][i], " at t = ", report.times_s[i], " s"));
        return report;
      }
    }
    spec::OutputValues values;
    values.name = scene.outputs[k].name;
    values.series_labels = {scene.outputs[k].name};
    values.series = {std::move(result->values[k])};
    report.outputs.push_back(std::move(values));
  }
  return report;
}

}  // namespace mbopt::fmu
