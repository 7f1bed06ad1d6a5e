#include "worker/engine/analysis.h"

#include <chrono>
#include <variant>

#include "worker/fmu/scene_analysis.h"
#include "worker/multibody/linkage_analysis.h"
#include "worker/multibody/scene_analysis.h"
#include "worker/solve/lumped_dynamics.h"

namespace mbopt::engine {

spec::AnalysisReport Analyze(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                             const ExternalAnalyzer* external) {
  const auto start = std::chrono::steady_clock::now();
  spec::AnalysisReport report;
  if (std::holds_alternative<spec::ExternalModel>(scene.model)) {
    if (external != nullptr) {
      report = external->AnalyzeExternal(scene, parameter_values_si);
    } else {
      report.formulation = spec::Formulation::kExternal;
      report.times_s = scene.time_grid.Instants();
      report.Fail(spec::FailureKind::kInvalidModel,
                  "external scene (driver \"" + std::get<spec::ExternalModel>(scene.model).driver +
                      "\"): this program runs no analysis drivers; run it on a worker that declares them "
                      "(mbopt-worker --drivers FILE)");
    }
  } else if (std::holds_alternative<spec::LumpedModel>(scene.model)) {
    report = solve::SimulateLumped(scene, parameter_values_si);
  } else if (std::holds_alternative<spec::MultibodyModel>(scene.model)) {
    report = multibody::AnalyzeMultibodyScene(scene, parameter_values_si);
  } else if (std::holds_alternative<spec::FmuModel>(scene.model)) {
    report = fmu::AnalyzeFmuScene(scene, parameter_values_si);
  } else {
    report = multibody::AnalyzeLinkageScene(scene, parameter_values_si);
  }
  report.counters.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

bool AppendCaseReport(const spec::Study& study, int c, spec::AnalysisReport report, spec::AnalysisReport* combined) {
  combined->counters += report.counters;
  if (c == 0) {
    combined->formulation = report.formulation;
    combined->times_s = report.times_s;
  }
  const std::string& name = study.cases[static_cast<size_t>(c)].name;
  if (!report.ok()) {
    combined->Fail(report.failure.kind, "load case " + name + ": " + report.failure.reason);
    return false;
  }
  for (spec::OutputValues& output : report.outputs) {
    output.name = name + "." + output.name;
    combined->outputs.push_back(std::move(output));
  }
  return true;
}

spec::AnalysisReport AnalyzeCases(const spec::Study& study, const std::vector<double>& parameter_values_si,
                                  const ExternalAnalyzer* external) {
  if (study.cases.empty()) return Analyze(study.scene, parameter_values_si, external);
  spec::AnalysisReport combined;
  for (int c = 0; c < study.num_cases(); ++c) {
    if (!AppendCaseReport(study, c, Analyze(study.scene, study.CaseParameterValues(c, parameter_values_si), external),
                          &combined)) {
      break;
    }
  }
  return combined;
}

}  // namespace mbopt::engine
