// An `external` scene analysed through the worker's declared drivers: the
// engine's ExternalAnalyzer (worker/engine/external_analyzer.h) for workers
// started with `--drivers FILE`.
//
// One analysis: the scene's driver is looked up among the declared ones;
// each scene input's value (an SI number of the scene's parameters) goes to
// the driver parameter of its name, which the runner writes with %.17g; the
// runner (runner.h) runs the driver; the results are mapped onto the
// scene's outputs:
//   external_value "v"   -> results' values["v"], one value (as mass is)
//   external_series "s"  -> results' series["s"] on the scene's time grid:
//     without a "time" array in the results, the series has one number per
//     grid instant and is taken as it is; with one, it is interpolated
//     linearly onto the grid instants, which must lie within its span.
// With sensitivities, the results' gradients (d result / d driver
// parameter) are carried to the scene's parameters through the inputs:
// d output / d p = sum over inputs of d output / d input * d input / d p
// (1 for an input that is the parameter, the expression's own partials for
// an expression); a series' gradient is put on the grid as the series is.
// Everything that goes wrong is a failed analysis with its reason: a driver
// this worker does not declare, an input the driver does not take, a
// parameter of the driver no input gives, a name missing from the results
// (naming the results file and what it does hold), and the runner's own
// failures (runner.h). Mapping is exact: no value passes through text.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "spec/analysis_report.h"
#include "spec/scene.h"
#include "worker/engine/external_analyzer.h"
#include "worker/external/driver.h"
#include "worker/external/results.h"

namespace mbopt::external {

// The worker's side of every external analysis, shared by all its tasks.
struct ExternalWorkerSettings {
  std::vector<DriverDeclaration> drivers;
  std::filesystem::path work_directory;  // where per-analysis folders go
  bool keep_run_folders = false;         // --keep-runs
  double kill_grace_s = 2.0;             // SIGTERM to SIGKILL at a time limit
  // Numbers the analyses of this process, so folder names never repeat
  // (a task retried on the same worker gets a new folder).
  mutable std::atomic<std::uint64_t> next_analysis{1};
};

// The values of the driver's parameters from `model`'s inputs at the scene's
// SI parameter values; InvalidArgument naming the input (inputs[i]) or the
// parameter when they do not match the driver's declaration.
absl::StatusOr<std::map<std::string, double>> DriverParameterValues(const DriverDeclaration& driver,
                                                                    const spec::ExternalModel& model,
                                                                    const std::vector<double>& parameter_values_si);

// The scene's outputs from a driver's results (see above). `results_file`
// names the file in messages. InvalidArgument names the output and the
// results file when a name is missing or a series does not fit the grid.
absl::StatusOr<std::vector<spec::OutputValues>> OutputsFromResults(const spec::Scene& scene,
                                                                    const ExternalResults& results,
                                                                    const std::string& results_file);

// d output / d scene parameter `parameters[k]`, [k][output][instant], from
// the results' gradients (see above). InvalidArgument names the output, the
// results file and the driver parameter whose derivative is missing.
absl::StatusOr<std::vector<std::vector<std::vector<double>>>> OutputDerivativesFromResults(
    const spec::Scene& scene, const ExternalResults& results, const std::vector<double>& parameter_values_si,
    const std::vector<int>& parameters, const std::string& results_file);

class ExternalSceneAnalyzer final : public engine::ExternalAnalyzer {
 public:
  // `settings` outlives the analyzer. `label` begins every analysis id
  // (and so folder name) of this analyzer, e.g. the task it serves; made
  // safe for a file name here.
  ExternalSceneAnalyzer(const ExternalWorkerSettings& settings, const std::string& label);

  spec::AnalysisReport AnalyzeExternal(const spec::Scene& scene,
                                       const std::vector<double>& parameter_values_si) const override;
  spec::AnalysisReport AnalyzeExternalWithSensitivities(
      const spec::Scene& scene, const std::vector<double>& parameter_values_si, const std::vector<int>& parameters,
      std::vector<std::vector<std::vector<double>>>* output_derivatives) const override;

 private:
  // Both of the above: derivatives only when `output_derivatives` is set.
  spec::AnalysisReport Analyze(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                               const std::vector<int>& parameters,
                               std::vector<std::vector<std::vector<double>>>* output_derivatives) const;

  const ExternalWorkerSettings& settings_;
  std::string label_;
};

// The declared driver of that name, or null.
const DriverDeclaration* FindDriver(const std::vector<DriverDeclaration>& drivers, const std::string& name);

}  // namespace mbopt::external
