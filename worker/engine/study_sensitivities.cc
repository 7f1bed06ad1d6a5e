#include "worker/engine/study_sensitivities.h"

#include <chrono>
#include <variant>

#include "worker/multibody/scene_analysis.h"
#include "worker/solve/lumped_sensitivity.h"

namespace mbopt::engine {

StudyAnalysisWithGradients AnalyzeStudyWithGradients(const spec::Study& study,
                                                     const spec::StudyLayout& layout,
                                                     const std::vector<double>& x_scaled) {
  const auto start = std::chrono::steady_clock::now();
  StudyAnalysisWithGradients out;
  const std::vector<double> parameters_si = study.ParameterValuesAt(x_scaled);
  std::vector<int> parameters;
  for (const spec::DesignVariable& v : study.variables) parameters.push_back(v.parameter);
  const bool multibody = std::holds_alternative<spec::MultibodyModel>(study.scene.model);
  out.gradients_unavailable = multibody ? multibody::MultibodySensitivityUnavailable(study.scene)
                                        : solve::LumpedSensitivityUnavailable(study.scene, parameters);
  if (!out.gradients_unavailable.empty()) {
    out.report = Analyze(study.scene, parameters_si);
    return out;
  }
  std::vector<std::vector<std::vector<double>>> output_derivatives;
  if (multibody) {
    multibody::MultibodySensitivityResult result =
        multibody::AnalyzeMultibodySceneWithSensitivities(study.scene, parameters_si, parameters);
    out.report = std::move(result.report);
    out.gradients_unavailable = std::move(result.unavailable);
    output_derivatives = std::move(result.output_derivatives);
  } else {
    solve::LumpedSensitivityResult result =
        solve::SimulateLumpedWithSensitivities(study.scene, parameters_si, parameters);
    out.report = std::move(result.report);
    output_derivatives = std::move(result.output_derivatives);
  }
  out.report.counters.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!out.report.ok()) {
    out.gradients_unavailable = "the analysis failed";
    return out;
  }
  if (!out.gradients_unavailable.empty()) return out;
  // One series per lumped output: wrap each derivative series.
  const size_t n = parameters.size();
  const size_t num_outputs = out.report.outputs.size();
  std::vector<std::vector<std::vector<std::vector<double>>>> wrapped(n);
  std::vector<std::vector<const std::vector<std::vector<double>>*>> derivatives(n);
  std::vector<const std::vector<std::vector<double>>*> values(num_outputs);
  for (size_t o = 0; o < num_outputs; ++o) values[o] = &out.report.outputs[o].series;
  for (size_t i = 0; i < n; ++i) {
    wrapped[i].resize(num_outputs);
    for (size_t o = 0; o < num_outputs; ++o) {
      wrapped[i][o] = {output_derivatives[i][o]};
      derivatives[i].push_back(&wrapped[i][o]);
    }
  }
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
