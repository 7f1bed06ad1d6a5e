// Forward dynamics of a ten-body planar mechanism with closed loops (the
// chain of tests/multibody/mechanisms.h, the same model as Simbody's in
// tests/oracle): 2 s at relative tolerance 1e-6, mbopt against Simbody in one
// run. mbopt is timed here by Google Benchmark (assembly included); Simbody
// by its own program (it cannot share a process with the engine), as the
// median of as many integrations. Prints the ratio at the end.
//
//   build/bench/multibody/bench_multibody --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "tests/multibody/mechanisms.h"
#include "worker/multibody/assembly.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/multibody/mechanism.h"

namespace {

using namespace mbopt::multibody;

constexpr double kTolerance = 1e-6;
constexpr double kEndS = 2.0;
constexpr int kIntervals = 200;

std::vector<double> Times() {
  std::vector<double> t;
  for (int i = 0; i <= kIntervals; ++i) t.push_back(kEndS * i / kIntervals);
  return t;
}

std::vector<double> g_mbopt_seconds;

void BM_TenBodyChainForwardDynamics(benchmark::State& state) {
  const Model model = testing::TenBodyChain();
  const std::vector<double> times = Times();
  ForwardDynamicsCounters counters;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const Mechanism m(model);
    const Assembly assembled = Assemble(m, 0.0);
    ForwardDynamicsOptions options;
    options.relative_tolerance = kTolerance;
    options.absolute_tolerance = kTolerance;
    counters = ForwardDynamicsCounters{};
    const mbopt::spec::AnalysisFailure f = IntegrateForward(
        m, 0.0, assembled.q, assembled.v, times, options,
        [](const MotionSample&) { return mbopt::spec::AnalysisFailure::Ok(); }, &counters);
    if (!f.ok()) state.SkipWithError(f.reason.c_str());
    g_mbopt_seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  state.counters["steps"] = static_cast<double>(counters.steps);
  state.counters["residuals"] = static_cast<double>(counters.residual_evaluations);
}
BENCHMARK(BM_TenBodyChainForwardDynamics)->Unit(benchmark::kMillisecond);

double SimbodyMedianSeconds(int repeats) {
  const std::string command = std::string(MBOPT_SIMBODY_ORACLE) + " ten_body_chain " + std::to_string(kTolerance) +
                              " " + std::to_string(kEndS) + " " + std::to_string(kIntervals) + " " +
                              std::to_string(repeats);
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return -1.0;
  double seconds = -1.0;
  if (std::fscanf(pipe, "%lf", &seconds) != 1) seconds = -1.0;
  return pclose(pipe) == 0 ? seconds : -1.0;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  if (g_mbopt_seconds.empty()) return 0;
  std::sort(g_mbopt_seconds.begin(), g_mbopt_seconds.end());
  const double mbopt_median = g_mbopt_seconds[g_mbopt_seconds.size() / 2];
  const double simbody_median = SimbodyMedianSeconds(5);
  if (simbody_median <= 0.0) {
    std::printf("Simbody: the oracle program failed\n");
    return 1;
  }
  std::printf("ten-body chain, 2 s at rtol 1e-6: mbopt median %.3f ms over %zu runs, Simbody median %.3f ms over 5: "
              "Simbody / mbopt = %.2f\n",
              1e3 * mbopt_median, g_mbopt_seconds.size(), 1e3 * simbody_median, simbody_median / mbopt_median);
  return 0;
}
