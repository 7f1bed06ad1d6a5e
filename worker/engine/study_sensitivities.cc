#include "worker/engine/study_sensitivities.h"

#include "spec/responses.h"
#include "worker/engine/model_kinds.h"

namespace mbopt::engine {

StudyAnalysisWithGradients AnalyzeStudyWithGradients(const spec::Study& study,
                                                     const spec::StudyLayout& layout,
                                                     const std::vector<double>& x_scaled,
                                                     const ExternalAnalyzer* external,
                                                     const budget::AnalysisBudget& budget) {
  StudyAnalysisWithGradients out;
  const std::vector<double> parameters_si = study.ParameterValuesAt(x_scaled);
  // Every parameter a variable sets (its own, then also_sets): the engine
  // differentiates with respect to each, and a variable's derivative is the
  // sum over the parameters it sets, which all take its value.
  std::vector<int> parameters;
  std::vector<size_t> variable_of;
  for (size_t i = 0; i < study.variables.size(); ++i) {
    const spec::DesignVariable& v = study.variables[i];
    parameters.push_back(v.parameter);
    variable_of.push_back(i);
    for (int also : v.also_sets) {
      parameters.push_back(also);
      variable_of.push_back(i);
    }
  }
  const ModelKind& kind = ModelKindOf(study.scene);
  out.gradients_unavailable = kind.sensitivities_unavailable(study.scene, parameters);
  if (!out.gradients_unavailable.empty() || kind.analyze_with_sensitivities == nullptr) {
    if (out.gradients_unavailable.empty()) out.gradients_unavailable = "no simulator sensitivities";
    out.report = AnalyzeCases(study, parameters_si, external, budget);
    return out;
  }
  // [parameter][signal][series]: every case's outputs in turn, as
  // AnalyzeCases orders them.
  std::vector<std::vector<std::vector<std::vector<double>>>> output_derivatives(parameters.size());
  for (int c = 0; c < study.num_cases(); ++c) {
    const std::vector<double> case_si = study.CaseParameterValues(c, parameters_si);
    budget::AnalysisBudget case_budget =
        budget.ForAnalysis(study.scene.integrator.max_wall_seconds, study.scene.integrator.max_steps);
    const double start_s = budget.NowSeconds();
    SensitivityAnalysis result = kind.analyze_with_sensitivities(study.scene, case_si, parameters, &case_budget, external);
    spec::AnalysisReport report = std::move(result.report);
    report.counters.wall_seconds = budget.NowSeconds() - start_s;
    if (out.gradients_unavailable.empty()) out.gradients_unavailable = std::move(result.unavailable);
    std::vector<std::vector<std::vector<std::vector<double>>>> derivatives = std::move(result.output_derivatives);
    const bool ok = report.ok();
    if (study.cases.empty()) {
      out.report = std::move(report);
    } else if (!AppendCaseReport(study, c, std::move(report), &out.report)) {
      break;
    }
    if (!ok) break;
    for (size_t k = 0; k < parameters.size() && k < derivatives.size(); ++k) {
      for (auto& series : derivatives[k]) output_derivatives[k].push_back(std::move(series));
    }
  }
  if (!out.report.ok()) {
    out.gradients_unavailable = "the analysis failed";
    return out;
  }
  if (!out.gradients_unavailable.empty()) return out;
  for (const auto& per_parameter : output_derivatives) {
    bool covered = per_parameter.size() == out.report.outputs.size();
    for (size_t o = 0; covered && o < per_parameter.size(); ++o) {
      covered = per_parameter[o].size() == out.report.outputs[o].series.size();
    }
    if (!covered) {
      out.gradients_unavailable = "the engine's sensitivities do not cover every output and series";
      return out;
    }
  }
  // Each output's derivative series, summed over the parameters of each
  // variable.
  const size_t n = study.variables.size();
  const size_t num_outputs = out.report.outputs.size();
  std::vector<std::vector<std::vector<std::vector<double>>>> wrapped(n);
  std::vector<std::vector<const std::vector<std::vector<double>>*>> derivatives(n);
  std::vector<const std::vector<std::vector<double>>*> values(num_outputs);
  for (size_t o = 0; o < num_outputs; ++o) values[o] = &out.report.outputs[o].series;
  for (size_t i = 0; i < n; ++i) wrapped[i].resize(num_outputs);
  for (size_t k = 0; k < parameters.size(); ++k) {
    const size_t i = variable_of[k];
    for (size_t o = 0; o < num_outputs; ++o) {
      const std::vector<std::vector<double>>& d = output_derivatives[k][o];
      if (wrapped[i][o].empty()) {
        wrapped[i][o] = d;
        continue;
      }
      for (size_t j = 0; j < d.size(); ++j) {
        std::vector<double>& sum = wrapped[i][o][j];
        for (size_t t = 0; t < sum.size() && t < d[j].size(); ++t) sum[t] += d[j][t];
      }
    }
  }
  for (size_t i = 0; i < n; ++i) {
    for (size_t o = 0; o < num_outputs; ++o) derivatives[i].push_back(&wrapped[i][o]);
  }
  std::vector<spec::Series> response_values;
  std::vector<std::vector<spec::Series>> response_derivatives;
  spec::AppendResponses(study, layout, parameters_si, &response_values, &values);
  spec::AppendResponseDerivatives(study, layout, parameters_si, values, &response_derivatives, &derivatives);
  absl::StatusOr<spec::StudyGradients> gradients =
      spec::ComputeStudyGradients(study, layout, values, derivatives);
  if (!gradients.ok()) {
    out.gradients_unavailable = std::string(gradients.status().message());
    return out;
  }
  out.gradients = *std::move(gradients);
  return out;
}

}  // namespace mbopt::engine
