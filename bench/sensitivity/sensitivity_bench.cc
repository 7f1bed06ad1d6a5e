// Cost of simulator sensitivities on the vehicle study (examples/vehicle) at
// its initial design and its own tolerances (rtol 1e-8, atol 1e-11): the
// plain analysis, the analysis with all six sensitivities (the settings in
// use), and the CVODES settings tried one at a time. Counters say where the
// work goes; `deriv_err` is the largest error of an output derivative series
// against a reference integrated at rtol 1e-12 / atol 1e-15, relative to the
// largest |value| of that series.
//
//   ninja -C build bench_sensitivity
//   build/bench/sensitivity/bench_sensitivity --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true   (one command line)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "spec/io/study_io.h"
#include "spec/layout.h"
#include "worker/engine/analysis.h"
#include "worker/engine/study_sensitivities.h"
#include "worker/engine/study_values.h"
#include "worker/lumped/lumped_sensitivity.h"

namespace {

using mbopt::lumped::LumpedSensitivityOptions;
using Derivatives = std::vector<std::vector<std::vector<double>>>;

mbopt::spec::Study LoadVehicle() {
  auto study = mbopt::spec::io::LoadStudyFile(std::string(MBOPT_SOURCE_DIR) +
                                              "/examples/vehicle/vehicle.study.textproto");
  if (!study.ok()) {
    std::cerr << study.status().message() << "\n";
    std::abort();
  }
  return *std::move(study);
}

std::vector<double> InitialDesign(const mbopt::spec::Study& study) {
  std::vector<double> x;
  for (const auto& v : study.variables) x.push_back(v.initial);
  return x;
}

std::vector<int> SensitivityParameters(const mbopt::spec::Study& study) {
  std::vector<int> parameters;
  for (const auto& v : study.variables) parameters.push_back(v.parameter);
  return parameters;
}

const Derivatives& Reference() {
  static const Derivatives reference = [] {
    mbopt::spec::Study study = LoadVehicle();
    study.scene.integrator.relative_tolerance = 1e-12;
    study.scene.integrator.absolute_tolerance = 1e-15;
    study.scene.integrator.max_steps = 10'000'000;
    LumpedSensitivityOptions options;
    options.method = LumpedSensitivityOptions::Method::kCvodesSensitivities;
    options.corrector = LumpedSensitivityOptions::Corrector::kSimultaneous;
    options.error_control = true;
    const auto result = mbopt::lumped::SimulateLumpedWithSensitivities(
        study.scene, study.ParameterValuesAt(InitialDesign(study)), SensitivityParameters(study),
        options);
    if (!result.report.ok()) {
      std::cerr << "reference failed: " << result.report.failure.reason << "\n";
      std::abort();
    }
    return result.output_derivatives;
  }();
  return reference;
}

double DerivativeError(const Derivatives& d) {
  const Derivatives& ref = Reference();
  double worst = 0.0;
  for (size_t k = 0; k < ref.size(); ++k) {
    for (size_t o = 0; o < ref[k].size(); ++o) {
      double scale = 0.0, error = 0.0;
      for (size_t i = 0; i < ref[k][o].size(); ++i) {
        scale = std::max(scale, std::abs(ref[k][o][i]));
        error = std::max(error, std::abs(d[k][o][i] - ref[k][o][i]));
      }
      if (scale > 0.0) worst = std::max(worst, error / scale);
    }
  }
  return worst;
}

void Count(benchmark::State& state, const mbopt::spec::AnalysisCounters& c) {
  state.counters["steps"] = static_cast<double>(c.time_steps);
  state.counters["rhs"] = static_cast<double>(c.rhs_evaluations);
  state.counters["jac"] = static_cast<double>(c.jacobian_evaluations);
  state.counters["newton"] = static_cast<double>(c.newton_iterations);
}

// The engine's usual path: one analysis without sensitivities.
void BM_VehiclePlainAnalysis(benchmark::State& state) {
  const mbopt::spec::Study study = LoadVehicle();
  const std::vector<double> p = study.ParameterValuesAt(InitialDesign(study));
  for (auto _ : state) {
    mbopt::spec::AnalysisReport report = mbopt::engine::Analyze(study.scene, p);
    if (!report.ok()) {
      state.SkipWithError(report.failure.reason.c_str());
      break;
    }
    benchmark::DoNotOptimize(report);
    Count(state, report.counters);
  }
}
BENCHMARK(BM_VehiclePlainAnalysis)->Unit(benchmark::kMicrosecond);

void RunSensitivities(benchmark::State& state, const LumpedSensitivityOptions& options) {
  const mbopt::spec::Study study = LoadVehicle();
  const std::vector<double> p = study.ParameterValuesAt(InitialDesign(study));
  const std::vector<int> parameters = SensitivityParameters(study);
  Reference();
  mbopt::lumped::LumpedSensitivityResult result;
  for (auto _ : state) {
    result = mbopt::lumped::SimulateLumpedWithSensitivities(study.scene, p, parameters, options);
    if (!result.report.ok()) {
      state.SkipWithError(result.report.failure.reason.c_str());
      return;
    }
    benchmark::DoNotOptimize(result);
  }
  Count(state, result.report.counters);
  state.counters["sens_rhs"] = static_cast<double>(result.counters.sensitivity_rhs_evaluations);
  state.counters["sens_newton"] =
      static_cast<double>(result.counters.sensitivity_newton_iterations);
  state.counters["setups"] = static_cast<double>(result.counters.linear_setups);
  state.counters["etf"] = static_cast<double>(result.counters.error_test_failures);
  state.counters["deriv_err"] = DerivativeError(result.output_derivatives);
}

// The analysis with all six sensitivities, with the settings in use.
void BM_VehicleSensitivityAnalysis(benchmark::State& state) { RunSensitivities(state, {}); }
BENCHMARK(BM_VehicleSensitivityAnalysis)->Unit(benchmark::kMicrosecond);

// The settings tried, each changed alone from the original ones (staggered
// corrector, error control on, EE tolerances, CVODES' default frequencies).
struct Variant {
  const char* label;
  LumpedSensitivityOptions options;
};
std::vector<Variant> Variants() {
  using C = LumpedSensitivityOptions::Corrector;
  LumpedSensitivityOptions base;
  base.method = LumpedSensitivityOptions::Method::kCvodesSensitivities;
  base.corrector = C::kStaggered;
  base.error_control = true;
  std::vector<Variant> v;
  v.push_back({"module, staggered (the former settings)", base});
  Variant x{"simultaneous", base};
  x.options.corrector = C::kSimultaneous;
  v.push_back(x);
  x = {"staggered1", base};
  x.options.corrector = C::kStaggered1;
  v.push_back(x);
  x = {"staggered, no sensitivity error control", base};
  x.options.error_control = false;
  v.push_back(x);
  x = {"simultaneous, no sensitivity error control", base};
  x.options.corrector = C::kSimultaneous;
  x.options.error_control = false;
  v.push_back(x);
  x = {"staggered, sensitivity tolerances x10", base};
  x.options.tolerance_factor = 10.0;
  v.push_back(x);
  x = {"staggered, sensitivity tolerances x100", base};
  x.options.tolerance_factor = 100.0;
  v.push_back(x);
  x = {"staggered, Jacobian every 1000 steps", base};
  x.options.jacobian_eval_frequency = 1000;
  v.push_back(x);
  x = {"staggered, setup every 100 steps", base};
  x.options.linear_setup_frequency = 100;
  v.push_back(x);
  x = {"augmented system, one WRMS norm over all blocks", {}};
  x.options.augmented_block_norm_bound = false;
  v.push_back(x);
  x = {"staggered, fused vector operations", base};
  x.options.fused_vector_operations = true;
  v.push_back(x);
  x = {"simultaneous, fused vector operations", base};
  x.options.corrector = C::kSimultaneous;
  x.options.fused_vector_operations = true;
  v.push_back(x);
  return v;
}

void BM_VehicleSensitivityVariant(benchmark::State& state) {
  const Variant variant = Variants()[static_cast<size_t>(state.range(0))];
  state.SetLabel(variant.label);
  RunSensitivities(state, variant.options);
}
BENCHMARK(BM_VehicleSensitivityVariant)
    ->DenseRange(0, static_cast<int>(Variants().size()) - 1, 1)
    ->Unit(benchmark::kMicrosecond);

// What an SLP cycle asks of a worker at the scene's own tolerances: the
// study values alone, or with their gradients (sensitivities plus the chain
// rule of the layout). `fd_analyses`: what forward differences spend instead
// of one analysis with gradients (n + 1); compare it with the ratio of the
// two medians.
void BM_VehicleStudyValues(benchmark::State& state) {
  const mbopt::spec::Study study = LoadVehicle();
  const auto layout = mbopt::spec::MakeStudyLayout(study);
  const std::vector<double> p = study.ParameterValuesAt(InitialDesign(study));
  mbopt::spec::AnalysisCounters counters;
  for (auto _ : state) {
    mbopt::spec::AnalysisReport report = mbopt::engine::Analyze(study.scene, p);
    auto values = mbopt::engine::ComputeStudyValues(study, *layout, report, p);
    if (!values.ok()) {
      state.SkipWithError(std::string(values.status().message()).c_str());
      return;
    }
    counters = report.counters;
    benchmark::DoNotOptimize(values);
  }
  state.counters["steps"] = static_cast<double>(counters.time_steps);
  state.counters["fd_analyses"] = static_cast<double>(study.variables.size() + 1);
}
BENCHMARK(BM_VehicleStudyValues)->Unit(benchmark::kMicrosecond);

void BM_VehicleStudyValuesWithGradients(benchmark::State& state) {
  const mbopt::spec::Study study = LoadVehicle();
  const auto layout = mbopt::spec::MakeStudyLayout(study);
  const std::vector<double> x = InitialDesign(study);
  std::int64_t steps = 0;
  for (auto _ : state) {
    mbopt::engine::StudyAnalysisWithGradients out =
        mbopt::engine::AnalyzeStudyWithGradients(study, *layout, x);
    if (!out.gradients.has_value()) {
      state.SkipWithError(out.gradients_unavailable.c_str());
      return;
    }
    steps = out.report.counters.time_steps;
    benchmark::DoNotOptimize(out);
  }
  state.counters["steps"] = static_cast<double>(steps);
  state.counters["fd_analyses"] = static_cast<double>(study.variables.size() + 1);
}
BENCHMARK(BM_VehicleStudyValuesWithGradients)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
