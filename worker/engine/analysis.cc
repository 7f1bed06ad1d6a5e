#include "worker/engine/analysis.h"

#include "worker/engine/model_kinds.h"

namespace mbopt::engine {

spec::AnalysisReport Analyze(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                             const ExternalAnalyzer* external, const budget::AnalysisBudget& budget) {
  budget::AnalysisBudget analysis_budget =
      budget.ForAnalysis(scene.integrator.max_wall_seconds, scene.integrator.max_steps);
  const double start_s = budget.NowSeconds();
  spec::AnalysisReport report = ModelKindOf(scene).analyze(scene, parameter_values_si, &analysis_budget, external);
  report.counters.wall_seconds = budget.NowSeconds() - start_s;
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
                                  const ExternalAnalyzer* external, const budget::AnalysisBudget& budget) {
  if (study.cases.empty()) return Analyze(study.scene, parameter_values_si, external, budget);
  spec::AnalysisReport combined;
  for (int c = 0; c < study.num_cases(); ++c) {
    if (!AppendCaseReport(study, c, Analyze(study.scene, study.CaseParameterValues(c, parameter_values_si), external, budget),
                          &combined)) {
      break;
    }
  }
  return combined;
}

}  // namespace mbopt::engine
