// What one multibody analysis with simulator sensitivities costs, in plain
// analyses of the same scene at the same design: the free-moving isolator
// (IDAS forward sensitivities, 2 parameters), the driven press
// (differentiated constraint equations, 2 link lengths) and the loaded knee
// in static equilibrium (the implicit function theorem at 101 equilibria,
// 3 parameters), and the co-rotational four-bar, whose outputs are its
// links' bending stresses at every node (IDAS forward sensitivities, the 3
// section areas). Forward differences cost 1 + n plain analyses for the same
// gradients; the aim is at most 1 + 0.4 n.
//
//   build/bench/multibody/bench_multibody_sensitivity --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "spec/io/study_io.h"
#include "worker/multibody/scene_analysis.h"

namespace {

using namespace mbopt;

spec::Scene Load(const std::string& path) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile(path);
  if (!scene.ok()) throw std::runtime_error(std::string(scene.status().message()));
  return *std::move(scene);
}

std::vector<double> Values(const spec::Scene& scene) {
  std::vector<double> p;
  for (const spec::Parameter& parameter : scene.parameters) p.push_back(parameter.value_si);
  return p;
}

void Plain(benchmark::State& state, const char* path) {
  const spec::Scene scene = Load(path);
  const std::vector<double> p = Values(scene);
  for (auto _ : state) {
    const spec::AnalysisReport report = multibody::AnalyzeMultibodyScene(scene, p);
    if (!report.ok()) state.SkipWithError(report.failure.reason.c_str());
    state.counters["steps"] = static_cast<double>(report.counters.time_steps);
  }
}

// The same analysis with the derivatives of every output with respect to
// every scene parameter.
void WithSensitivities(benchmark::State& state, const char* path) {
  const spec::Scene scene = Load(path);
  const std::vector<double> p = Values(scene);
  std::vector<int> parameters;
  for (size_t i = 0; i < p.size(); ++i) parameters.push_back(static_cast<int>(i));
  for (auto _ : state) {
    const multibody::MultibodySensitivityResult result =
        multibody::AnalyzeMultibodySceneWithSensitivities(scene, p, parameters);
    if (!result.report.ok() || !result.unavailable.empty()) state.SkipWithError("no sensitivities");
    state.counters["steps"] = static_cast<double>(result.report.counters.time_steps);
  }
}

BENCHMARK_CAPTURE(Plain, isolator, "examples/isolator/isolator.scene.textproto")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(WithSensitivities, isolator, "examples/isolator/isolator.scene.textproto")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(Plain, press, "examples/press/press.scene.textproto")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(WithSensitivities, press, "examples/press/press.scene.textproto")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(Plain, knee_statics, "tests/multibody/knee_statics.scene.textproto")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(WithSensitivities, knee_statics, "tests/multibody/knee_statics.scene.textproto")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(Plain, fourbar_corotational, "examples/fourbar/fourbar_corotational.scene.textproto")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(WithSensitivities, fourbar_corotational, "examples/fourbar/fourbar_corotational.scene.textproto")
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
