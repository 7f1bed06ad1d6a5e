// Speed of one linkage analysis per formulation, on the reference problems.
//   bench_linkage --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include "tests/linkage/linkage_scenes.h"
#include "worker/multibody/linkage_analysis.h"

namespace mbopt {
namespace {

// Kinematic: the landing gear's 2 rad sweep at the initial design.
void BM_LandingGearKinematic(benchmark::State& state) {
  const spec::Scene scene = linkage_testing::LandingGearScene();
  const std::vector<double> p =
      linkage_testing::LandingGearDesign({100, 110, 130, 110, 160, 155, 180, 100, -2.0});
  for (auto _ : state) {
    spec::AnalysisReport r = multibody::AnalyzeLinkageScene(scene, p);
    if (!r.ok()) state.SkipWithError(r.failure.reason.c_str());
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_LandingGearKinematic)->Unit(benchmark::kMicrosecond);

// Kinetostatic: rigid four-bar, 3 links x 7 nodes x 101 instants.
void BM_FourBarKinetostatic(benchmark::State& state) {
  const spec::Scene scene = linkage_testing::FourBarScene();
  const std::vector<double> p = {9.65e-4, 3.92e-4, 2.69e-4};
  for (auto _ : state) {
    spec::AnalysisReport r = multibody::AnalyzeLinkageScene(scene, p);
    if (!r.ok()) state.SkipWithError(r.failure.reason.c_str());
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_FourBarKinetostatic)->Unit(benchmark::kMicrosecond);

// Elastodynamic: 6 elements per link, rotary inertia, 5 % damping, 0.5 s
// simulated (report's optimum areas), scene default tolerances 1e-6 / 1e-9.
void BM_FourBarElastodynamic(benchmark::State& state) {
  linkage_testing::FourBarOptions o;
  o.elements = 6;
  o.rotary_inertia = true;
  o.damping = true;
  const spec::Scene scene = linkage_testing::FourBarScene(o);
  const std::vector<double> p = {9.65e-4, 3.92e-4, 2.69e-4};
  for (auto _ : state) {
    spec::AnalysisReport r = multibody::AnalyzeLinkageScene(scene, p);
    if (!r.ok()) state.SkipWithError(r.failure.reason.c_str());
    state.counters["steps"] = static_cast<double>(r.counters.time_steps);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_FourBarElastodynamic)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace mbopt

BENCHMARK_MAIN();
