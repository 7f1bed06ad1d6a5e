// The LP the SLP core solves once per cycle, at the size of a time-gridded
// study: 10 design variables (as box-limited steps d = x - x0), the
// infeasibility variable s, and 1000 dense linearized constraint rows
// (10 responses x 101 time points, rounded). Successive LPs differ slightly,
// as the linearizations of successive cycles do, so each solve starts from the
// previous optimal basis.
//
//   build-core/bench/lp/bench_lp --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true   (one command line)
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "server/lp/linear_program.h"
#include "server/lp/make_clp_lp_solver.h"

namespace {

using mbopt::lp::LinearProgram;

constexpr int kDesignVariables = 10;
constexpr int kRows = 1000;
constexpr int kVariants = 64;  // distinct "cycles" cycled through

// One cycle's LP: minimize g_F . d + penalty * s subject to
// g_h(x0) + grad g_h . d - s * scale_h <= c_h, |d_i| <= w_i, s >= 0.
// `cycle` perturbs values and gradients by a few percent.
LinearProgram CycleLp(int cycle) {
  std::mt19937 base(2024);
  std::mt19937 noise(1000 + cycle);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> small(-0.03, 0.03);
  const int n = kDesignVariables + 1;
  LinearProgram lp;
  lp.objective.resize(n);
  lp.column_lower.resize(n);
  lp.column_upper.resize(n);
  for (int j = 0; j < kDesignVariables; ++j) {
    lp.objective[j] = u(base) * (1.0 + small(noise));
    const double w = 0.2 * (1.0 + small(noise));
    lp.column_lower[j] = -w;
    lp.column_upper[j] = w;
  }
  lp.objective[kDesignVariables] = 1e3;
  lp.column_lower[kDesignVariables] = 0.0;
  lp.column_upper[kDesignVariables] = std::numeric_limits<double>::infinity();
  lp.rows.resize(kRows, n);
  lp.row_lower = Eigen::VectorXd::Constant(kRows, -std::numeric_limits<double>::infinity());
  lp.row_upper.resize(kRows);
  for (int i = 0; i < kRows; ++i) {
    // Rows of one response along a time grid are smooth in time.
    const double t = (i % 101) / 100.0;
    for (int j = 0; j < kDesignVariables; ++j) {
      lp.rows(i, j) = (u(base) + std::sin(6.0 * t + j)) * (1.0 + small(noise));
    }
    lp.rows(i, kDesignVariables) = -1.0;
    // Normalized value (g - c)/scale at x0, between -0.6 and +0.05.
    lp.row_upper[i] = -(-0.6 + 0.65 * (0.5 + 0.5 * u(base))) + small(noise);
  }
  return lp;
}

void BM_SlpCycleLpWarm(benchmark::State& state) {
  std::vector<LinearProgram> lps;
  for (int c = 0; c < kVariants; ++c) lps.push_back(CycleLp(c));
  auto solver = mbopt::lp::MakeClpLpSolver();
  solver->Solve(lps[0]);
  int next = 1;
  int warm = 0, solves = 0, failures = 0;
  long iterations = 0;
  for (auto _ : state) {
    const auto s = solver->Solve(lps[next]);
    benchmark::DoNotOptimize(s.objective_value);
    warm += s.warm_started ? 1 : 0;
    iterations += s.iterations;
    failures += s.status == mbopt::lp::LpStatus::kOptimal ? 0 : 1;
    ++solves;
    next = (next + 1) % kVariants;
  }
  state.counters["warm_fraction"] = solves ? static_cast<double>(warm) / solves : 0.0;
  state.counters["non_optimal"] = failures;
  state.counters["simplex_iterations"] = solves ? static_cast<double>(iterations) / solves : 0.0;
}
BENCHMARK(BM_SlpCycleLpWarm)->Unit(benchmark::kMicrosecond);

void BM_SlpCycleLpCold(benchmark::State& state) {
  std::vector<LinearProgram> lps;
  for (int c = 0; c < kVariants; ++c) lps.push_back(CycleLp(c));
  int next = 0;
  long iterations = 0, solves = 0;
  for (auto _ : state) {
    auto solver = mbopt::lp::MakeClpLpSolver();
    const auto s = solver->Solve(lps[next]);
    benchmark::DoNotOptimize(s.objective_value);
    iterations += s.iterations;
    ++solves;
    next = (next + 1) % kVariants;
  }
  state.counters["simplex_iterations"] = solves ? static_cast<double>(iterations) / solves : 0.0;
}
BENCHMARK(BM_SlpCycleLpCold)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
