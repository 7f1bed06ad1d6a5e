#include "worker/engine/analysis.h"

#include <chrono>
#include <variant>

#include "worker/multibody/scene_analysis.h"
#include "worker/solve/lumped_dynamics.h"
#ifdef MBOPT_HAVE_LINKAGE
#include "worker/solve/linkage_analysis.h"
#endif

namespace mbopt::engine {

spec::AnalysisReport Analyze(const spec::Scene& scene, const std::vector<double>& parameter_values_si) {
  const auto start = std::chrono::steady_clock::now();
  spec::AnalysisReport report;
  if (std::holds_alternative<spec::LumpedModel>(scene.model)) {
    report = solve::SimulateLumped(scene, parameter_values_si);
  } else if (std::holds_alternative<spec::MultibodyModel>(scene.model)) {
    report = multibody::AnalyzeMultibodyScene(scene, parameter_values_si);
  } else {
#ifdef MBOPT_HAVE_LINKAGE
    report = solve::AnalyzeLinkage(scene, parameter_values_si);
#else
    report.times_s = scene.time_grid.Instants();
    report.Fail(spec::FailureKind::kInvalidModel, "linkage scenes are not available in this build");
#endif
  }
  report.counters.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace mbopt::engine
