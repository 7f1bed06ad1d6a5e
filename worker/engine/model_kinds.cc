#include "worker/engine/model_kinds.h"

#include <utility>
#include <variant>

#include "common/check.h"
#include "worker/fmu/scene_analysis.h"
#include "worker/lumped/lumped_dynamics.h"
#include "worker/lumped/lumped_sensitivity.h"
#include "worker/multibody/linkage_analysis.h"
#include "worker/multibody/scene_analysis.h"
#include "worker/spatial/spatial_scene_analysis.h"

namespace mbopt::engine {
namespace {

using SceneModel = decltype(spec::Scene::model);

// Where alternative T sits in spec::Scene::model: the table is laid out by
// it, so a new alternative without an entry fails at start-up, not with a
// wrong dispatch.
template <class T>
size_t IndexOf() {
  return SceneModel(std::in_place_type<T>).index();
}

spec::AnalysisReport FailedAtStart(const spec::Scene& scene, spec::AnalysisFailure failure) {
  spec::AnalysisReport report;
  report.times_s = scene.time_grid.Instants();
  report.Fail(failure.kind, std::move(failure.reason));
  return report;
}

std::string Never(const char* why) { return why; }

spec::AnalysisReport AnalyzeLumped(const spec::Scene& scene, const std::vector<double>& p,
                                   budget::AnalysisBudget* budget, const ExternalAnalyzer*) {
  lumped::LumpedDynamicsOptions options;
  options.budget = budget;
  return lumped::SimulateLumped(scene, p, options);
}

SensitivityAnalysis AnalyzeLumpedWithSensitivities(const spec::Scene& scene, const std::vector<double>& p,
                                                   const std::vector<int>& parameters,
                                                   budget::AnalysisBudget* budget, const ExternalAnalyzer*) {
  lumped::LumpedSensitivityOptions options;
  options.budget = budget;
  lumped::LumpedSensitivityResult result = lumped::SimulateLumpedWithSensitivities(scene, p, parameters, options);
  return {std::move(result.report), OneSeriesPerOutput(std::move(result.output_derivatives)), ""};
}

spec::AnalysisReport AnalyzeLinkage(const spec::Scene& scene, const std::vector<double>& p,
                                    budget::AnalysisBudget* budget, const ExternalAnalyzer*) {
  return multibody::AnalyzeLinkageScene(scene, p, budget);
}

spec::AnalysisReport AnalyzeMultibody(const spec::Scene& scene, const std::vector<double>& p,
                                      budget::AnalysisBudget* budget, const ExternalAnalyzer*) {
  return multibody::AnalyzeMultibodyScene(scene, p, budget);
}

SensitivityAnalysis AnalyzeMultibodyWithSensitivities(const spec::Scene& scene, const std::vector<double>& p,
                                                      const std::vector<int>& parameters,
                                                      budget::AnalysisBudget* budget, const ExternalAnalyzer*) {
  multibody::MultibodySensitivityResult result =
      multibody::AnalyzeMultibodySceneWithSensitivities(scene, p, parameters, budget);
  return {std::move(result.report), std::move(result.output_derivatives), std::move(result.unavailable)};
}

spec::AnalysisReport AnalyzeSpatial(const spec::Scene& scene, const std::vector<double>& p,
                                    budget::AnalysisBudget* budget, const ExternalAnalyzer*) {
  return spatial::AnalyzeSpatialScene(scene, p, budget);
}

SensitivityAnalysis AnalyzeSpatialWithSensitivities(const spec::Scene& scene, const std::vector<double>& p,
                                                    const std::vector<int>& parameters,
                                                    budget::AnalysisBudget* budget, const ExternalAnalyzer*) {
  spatial::SpatialSensitivityResult result = spatial::AnalyzeSpatialSceneWithSensitivities(scene, p, parameters, budget);
  return {std::move(result.report), OneSeriesPerOutput(std::move(result.output_derivatives)),
          std::move(result.unavailable)};
}

spec::AnalysisReport AnalyzeFmu(const spec::Scene& scene, const std::vector<double>& p,
                                budget::AnalysisBudget* budget, const ExternalAnalyzer*) {
  return fmu::AnalyzeFmuScene(scene, p, budget);
}

SensitivityAnalysis AnalyzeFmuWithSensitivities(const spec::Scene& scene, const std::vector<double>& p,
                                                const std::vector<int>& parameters, budget::AnalysisBudget* budget,
                                                const ExternalAnalyzer*) {
  fmu::FmuSensitivityAnalysis result = fmu::AnalyzeFmuSceneWithSensitivities(scene, p, parameters, budget);
  return {std::move(result.report), OneSeriesPerOutput(std::move(result.output_derivatives)),
          std::move(result.unavailable)};
}

spec::AnalysisReport AnalyzeExternal(const spec::Scene& scene, const std::vector<double>& p,
                                     budget::AnalysisBudget* budget, const ExternalAnalyzer* external) {
  // The driver's process has its own time limit (worker/external); a
  // cancelled analysis is stopped before it starts.
  if (spec::AnalysisFailure spent = budget->Check(0.0); !spent.ok()) return FailedAtStart(scene, std::move(spent));
  if (external != nullptr) return external->AnalyzeExternal(scene, p);
  spec::AnalysisReport report = FailedAtStart(
      scene, spec::AnalysisFailure::Of(spec::FailureKind::kInvalidModel,
                                       "external scene (driver \"" + std::get<spec::ExternalModel>(scene.model).driver +
                                           "\"): this program runs no analysis drivers; run it on a worker that "
                                           "declares them (mbopt-worker --drivers FILE)"));
  report.formulation = spec::Formulation::kExternal;
  return report;
}

SensitivityAnalysis AnalyzeExternalWithSensitivities(const spec::Scene& scene, const std::vector<double>& p,
                                                     const std::vector<int>& parameters,
                                                     budget::AnalysisBudget* budget, const ExternalAnalyzer* external) {
  SensitivityAnalysis out;
  if (external == nullptr) {
    out.report = AnalyzeExternal(scene, p, budget, external);
    out.unavailable = "no analysis drivers in this program";
    return out;
  }
  if (spec::AnalysisFailure spent = budget->Check(0.0); !spent.ok()) {
    out.report = FailedAtStart(scene, std::move(spent));
    return out;
  }
  std::vector<std::vector<std::vector<double>>> derivatives;
  out.report = external->AnalyzeExternalWithSensitivities(scene, p, parameters, &derivatives);
  out.output_derivatives = OneSeriesPerOutput(std::move(derivatives));
  return out;
}

std::vector<ModelKind> MakeTable() {
  std::vector<ModelKind> table(std::variant_size_v<SceneModel>);
  table[IndexOf<spec::LumpedModel>()] = {
      "lumped",
      "small-motion linear dynamics M q'' + C q' + K q = f(t), integrated by CVODES (worker/lumped/lumped_dynamics.h)",
      "time_steps, rhs_evaluations, jacobian_evaluations (Newton matrix factorizations) and newton_iterations "
      "of CVODES",
      &AnalyzeLumped,
      [](const spec::Scene& scene, const std::vector<int>& parameters) {
        return lumped::LumpedSensitivityUnavailable(scene, parameters);
      },
      &AnalyzeLumpedWithSensitivities};
  table[IndexOf<spec::LinkageModel>()] = {
      "linkage",
      "compiled to the multibody engine: kinematics, kinetostatics (inverse dynamics), or elastodynamics of flexible links in the floating-frame or co-rotational formulation (worker/multibody/linkage_analysis.h)",
      "position_solves and newton_iterations of the kinematic continuation; time_steps, rhs_evaluations, "
      "jacobian_evaluations and newton_iterations of CVODES for flexible links",
      &AnalyzeLinkage,
      [](const spec::Scene&, const std::vector<int>&) {
        return Never("a linkage analysis has no simulator sensitivities: its kinematic sweep and floating-frame "
                     "integration are not differentiated");
      },
      nullptr};
  table[IndexOf<spec::MultibodyModel>()] = {
      "multibody",
      "kinematics with inverse dynamics, static equilibrium (KINSOL) or forward dynamics (IDAS) of a planar "
      "multibody system, chosen by its degrees of freedom (worker/multibody/scene_analysis.h)",
      "position_solves and newton_iterations of kinematic and static sweeps (rhs_evaluations: KINSOL's "
      "residuals); time_steps, rhs_evaluations (residuals), jacobian_evaluations and newton_iterations of IDAS",
      &AnalyzeMultibody,
      [](const spec::Scene& scene, const std::vector<int>&) {
        return multibody::MultibodySensitivityUnavailable(scene);
      },
      &AnalyzeMultibodyWithSensitivities};
  table[IndexOf<spec::ExternalModel>()] = {
      "external",
      "a simulation code the worker declares, run in its own folder and process group (worker/external)",
      "wall_seconds only: the driver's work is its own",
      &AnalyzeExternal,
      // Whether the driver writes gradients shows only in its results: one
      // that writes none fails the analysis saying so.
      [](const spec::Scene&, const std::vector<int>&) { return std::string(); },
      &AnalyzeExternalWithSensitivities};
  table[IndexOf<spec::FmuModel>()] = {
      "fmu",
      "an FMI 2.0 or 3.0 FMU: Model Exchange integrated by CVODES with its events, or Co-Simulation stepped "
      "(worker/fmu/scene_analysis.h)",
      "time_steps: CVODES steps (Model Exchange) or fmi2DoStep / fmi3DoStep calls (Co-Simulation)",
      &AnalyzeFmu,
      [](const spec::Scene& scene, const std::vector<int>& parameters) {
        return fmu::FmuSensitivitiesUnavailable(scene, parameters);
      },
      &AnalyzeFmuWithSensitivities};
  table[IndexOf<spec::SpatialModel>()] = {
      "spatial",
      "forward dynamics (IDAS, the GGL form) of a spatial multibody system in absolute coordinates with Euler "
      "parameters, driven or free (worker/spatial/spatial_scene_analysis.h)",
      "newton_iterations of assembly and IDAS; time_steps, rhs_evaluations (residuals) and jacobian_evaluations "
      "of IDAS",
      &AnalyzeSpatial,
      // Every output and parameter has them; a mechanism with redundant
      // joints, found only at assembly, says so from its analysis.
      [](const spec::Scene&, const std::vector<int>&) { return std::string(); },
      &AnalyzeSpatialWithSensitivities};
  for (const ModelKind& kind : table) MBOPT_CHECK(kind.analyze != nullptr, "a scene model kind has no table entry");
  return table;
}

}  // namespace

std::vector<std::vector<std::vector<std::vector<double>>>> OneSeriesPerOutput(
    std::vector<std::vector<std::vector<double>>> derivatives) {
  std::vector<std::vector<std::vector<std::vector<double>>>> out(derivatives.size());
  for (size_t k = 0; k < derivatives.size(); ++k) {
    out[k].reserve(derivatives[k].size());
    for (std::vector<double>& series : derivatives[k]) out[k].push_back({std::move(series)});
  }
  return out;
}

const std::vector<ModelKind>& ModelKinds() {
  static const std::vector<ModelKind> table = MakeTable();
  return table;
}

const ModelKind& ModelKindOf(const spec::Scene& scene) { return ModelKinds()[scene.model.index()]; }

}  // namespace mbopt::engine
