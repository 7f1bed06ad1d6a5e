// How the engine runs an `external` scene: it does not. An external scene is
// analysed by a simulation code the worker declares (worker/external), which
// means files and processes, which the engine never touches; the worker
// hands the engine an ExternalAnalyzer and the engine calls it where it
// would call a solver. Without one, an external scene is a failed analysis
// saying so (in-process runs, a worker that declares no drivers).
#pragma once

#include <vector>

#include "spec/analysis_report.h"
#include "spec/scene.h"

namespace mbopt::engine {

class ExternalAnalyzer {
 public:
  virtual ~ExternalAnalyzer() = default;
  // One analysis of `scene` (its model is a spec::ExternalModel) at one SI
  // value per scene parameter: the report's outputs are the scene's, in its
  // order, on its time grid (or one value for an external_value output).
  // Failures are data, as for every analysis. Called from several threads
  // at once when the worker has several slots.
  virtual spec::AnalysisReport AnalyzeExternal(const spec::Scene& scene,
                                               const std::vector<double>& parameter_values_si) const = 0;
  // The same analysis, with the derivatives of its outputs with respect to
  // the scene parameters `parameters` in `output_derivatives`
  // ([k][output][instant], one series per output), from the gradients the
  // simulation code writes. A code that writes none the study needs makes
  // the analysis fail saying so: the study asked for them.
  virtual spec::AnalysisReport AnalyzeExternalWithSensitivities(
      const spec::Scene& scene, const std::vector<double>& parameter_values_si, const std::vector<int>& parameters,
      std::vector<std::vector<std::vector<double>>>* output_derivatives) const = 0;
};

}  // namespace mbopt::engine
