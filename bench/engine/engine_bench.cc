// Speed of one analysis of the vehicle benchmark (examples/vehicle): the cost
// unit of an SLP cycle (7 analyses per cycle with forward differences).
//
//   ninja -C build bench_engine
//   build/bench/engine/bench_engine --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true   (one command line)
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <iostream>

#include "spec/io/study_io.h"
#include "spec/layout.h"
#include "worker/engine/analysis.h"
#include "worker/engine/study_values.h"
#include "worker/lumped/lumped_dynamics.h"

namespace {

mbopt::spec::Study LoadVehicle(double relative_tolerance) {
  auto study = mbopt::spec::io::LoadStudyFile(std::string(MBOPT_SOURCE_DIR) +
                                              "/examples/vehicle/vehicle.study.textproto");
  if (!study.ok()) {
    std::cerr << study.status().message() << "\n";
    std::abort();
  }
  study->scene.integrator.relative_tolerance = relative_tolerance;
  study->scene.integrator.absolute_tolerance = 1e-9;
  return *std::move(study);
}

std::vector<double> InitialDesign(const mbopt::spec::Study& study) {
  std::vector<double> x;
  for (const auto& v : study.variables) x.push_back(v.initial);
  return x;
}

// The analysis alone, at rtol 1e-6 / atol 1e-9 (the engine's defaults).
void BM_VehicleAnalysis_Rtol1e6(benchmark::State& state) {
  const mbopt::spec::Study study = LoadVehicle(1e-6);
  const std::vector<double> p = study.ParameterValuesAt(InitialDesign(study));
  for (auto _ : state) {
    mbopt::spec::AnalysisReport report = mbopt::engine::Analyze(study.scene, p);
    if (!report.ok()) {
      state.SkipWithError(report.failure.reason.c_str());
      break;
    }
    benchmark::DoNotOptimize(report);
    state.counters["steps"] = static_cast<double>(report.counters.time_steps);
  }
}
BENCHMARK(BM_VehicleAnalysis_Rtol1e6)->Unit(benchmark::kMicrosecond);

// At the example's own accuracy (rtol 1e-8), plus the study values.
void BM_VehicleAnalysisAndValues_Rtol1e8(benchmark::State& state) {
  const mbopt::spec::Study study = LoadVehicle(1e-8);
  const auto layout = mbopt::spec::MakeStudyLayout(study);
  const std::vector<double> p = study.ParameterValuesAt(InitialDesign(study));
  for (auto _ : state) {
    mbopt::spec::AnalysisReport report = mbopt::engine::Analyze(study.scene, p);
    auto values = mbopt::engine::ComputeStudyValues(study, *layout, report, p);
    if (!values.ok()) {
      state.SkipWithError(std::string(values.status().message()).c_str());
      break;
    }
    benchmark::DoNotOptimize(values);
    state.counters["steps"] = static_cast<double>(report.counters.time_steps);
  }
}
BENCHMARK(BM_VehicleAnalysisAndValues_Rtol1e8)->Unit(benchmark::kMicrosecond);

// The lumped formulation directly, BDF vs Adams (Newton / fixed point).
void BM_VehicleLumpedMethod_Rtol1e6(benchmark::State& state) {
  const mbopt::spec::Study study = LoadVehicle(1e-6);
  const std::vector<double> p = study.ParameterValuesAt(InitialDesign(study));
  mbopt::lumped::LumpedDynamicsOptions options;
  options.adams = state.range(0) > 0;
  options.fixed_point = state.range(0) > 1;
  for (auto _ : state) {
    mbopt::spec::AnalysisReport report = mbopt::lumped::SimulateLumped(study.scene, p, options);
    benchmark::DoNotOptimize(report);
    state.counters["steps"] = static_cast<double>(report.counters.time_steps);
  }
}
BENCHMARK(BM_VehicleLumpedMethod_Rtol1e6)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

void BM_VehicleAtol_Rtol1e6(benchmark::State& state) {
  mbopt::spec::Study study = LoadVehicle(1e-6);
  study.scene.integrator.absolute_tolerance = std::pow(10.0, -static_cast<double>(state.range(0)));
  const std::vector<double> p = study.ParameterValuesAt(InitialDesign(study));
  for (auto _ : state) {
    mbopt::spec::AnalysisReport report = mbopt::engine::Analyze(study.scene, p);
    benchmark::DoNotOptimize(report);
    state.counters["steps"] = static_cast<double>(report.counters.time_steps);
  }
}
BENCHMARK(BM_VehicleAtol_Rtol1e6)->DenseRange(6, 10, 1)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
