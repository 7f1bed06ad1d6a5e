// bench_stopping_rule: where the SLP core stops on the analytic problems of
// tests/slp/test_problems.h (published optima), from the published start and
// from random starts inside the bounds, with the report's convergence test
// alone ("report") and with the first-order optimality check added
// ("report+KKT", the default). Prints, per rule: runs that ended converged,
// the median and worst relative distance of the result's F from the optimum,
// runs within 0.1 % of it, and the median analyses. Deterministic (seeded).
//
//   build/bench/stopping/bench_stopping_rule [--starts N] [--tolerance T]
//
// With MBOPT_STOPPING_DEBUG set, every run that ends more than 1 % from the
// optimum is printed on stderr cycle by cycle (F, KKT residual, move limits).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "server/lp/make_clp_lp_solver.h"
#include "server/slp/slp_optimizer.h"
#include "tests/slp/test_problems.h"
#include "tests/slp_testing/drive_optimizer.h"

namespace mbopt::slp::testing {
namespace {

struct RuleSummary {
  int runs = 0;
  int converged = 0;
  int within_1e3 = 0;
  std::vector<double> errors;
  std::vector<double> analyses;
};

double Median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void RunOne(const TestProblem& p, const SlpOptions& options, RuleSummary* summary) {
  SlpOptimizer optimizer(p.spec, options, lp::MakeClpLpSolver());
  absl::StatusOr<RunOutcome> out = RunToCompletion(optimizer, MakeEvaluator(p));
  ++summary->runs;
  if (!out.ok()) return;
  if (out->state == RunState::kConverged) ++summary->converged;
  const double error = std::abs(out->objective - p.optimum_objective) /
                       std::max(std::abs(p.optimum_objective), 1e-12);
  // An infeasible result is as far from the optimum as it gets.
  const double counted = out->max_violation > options.convergence_violation_tolerance
                             ? std::numeric_limits<double>::infinity()
                             : error;
  summary->errors.push_back(counted);
  if (counted < 1e-3) ++summary->within_1e3;
  summary->analyses.push_back(static_cast<double>(out->analyses));
  if (std::getenv("MBOPT_STOPPING_DEBUG") != nullptr && counted > 1e-2) {
    std::cerr << p.name << " start " << p.spec.initial.transpose() << " -> " << out->design.transpose()
              << " F=" << out->objective << " state " << RunStateName(out->state) << "\n";
    for (const CycleRecord& r : out->records) {
      std::cerr << "  c" << r.cycle << "." << r.attempt << " acc=" << r.accepted << " F*=" << r.objective_trial
                << " kkt=" << r.optimality_residual << " ml=" << r.move_limits.transpose() << " x*="
                << r.x_trial.transpose() << "\n";
    }
  }
}

int Main(int argc, char** argv) {
  int starts = 20;
  double tolerance = SlpOptions{}.convergence_optimality_tolerance;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--starts" && i + 1 < argc) {
      starts = std::atoi(argv[++i]);
    } else if (arg == "--tolerance" && i + 1 < argc) {
      tolerance = std::atof(argv[++i]);
    } else {
      std::cerr << "usage: bench_stopping_rule [--starts N] [--tolerance T]\n";
      return 2;
    }
  }
  const std::vector<TestProblem> problems = {Hs21(),  Hs35(),  Hs35BadlyScaled(), Hs43(),
                                             Hs76(),  Hs100(), Cb2(),             ChebyshevExp()};
  SlpOptions report;
  report.convergence_optimality_tolerance = std::numeric_limits<double>::max();
  SlpOptions with_kkt;
  with_kkt.convergence_optimality_tolerance = tolerance;

  std::cout << absl::StrFormat(
      "Stopping rule on %d analytic problems, published start + %d random starts each; "
      "KKT tolerance %g\n\n",
      problems.size(), starts, tolerance);
  std::cout << "| problem | rule | converged | median |F-F*|/|F*| | worst | within 0.1 % | median analyses |\n"
               "|---|---|---|---|---|---|---|\n";
  RuleSummary total_report, total_kkt;
  std::mt19937_64 rng(20261125);
  for (const TestProblem& problem : problems) {
    RuleSummary s_report, s_kkt;
    for (int k = 0; k <= starts; ++k) {
      TestProblem p = problem;
      if (k > 0) {
        for (int i = 0; i < p.spec.num_variables(); ++i) {
          std::uniform_real_distribution<double> u(p.spec.lower[i], p.spec.upper[i]);
          p.spec.initial[i] = u(rng);
        }
      }
      RunOne(p, report, &s_report);
      RunOne(p, with_kkt, &s_kkt);
    }
    for (const auto& [name, s, total] :
         {std::tuple{"report", &s_report, &total_report}, std::tuple{"report+KKT", &s_kkt, &total_kkt}}) {
      std::cout << absl::StrFormat("| %s | %s | %d/%d | %.2e | %.2e | %d/%d | %.0f |\n", problem.name, name,
                                   s->converged, s->runs, Median(s->errors),
                                   *std::max_element(s->errors.begin(), s->errors.end()), s->within_1e3,
                                   s->runs, Median(s->analyses));
      total->runs += s->runs;
      total->converged += s->converged;
      total->within_1e3 += s->within_1e3;
      total->errors.insert(total->errors.end(), s->errors.begin(), s->errors.end());
      total->analyses.insert(total->analyses.end(), s->analyses.begin(), s->analyses.end());
    }
  }
  for (const auto& [name, s] : {std::pair{"report", &total_report}, std::pair{"report+KKT", &total_kkt}}) {
    std::cout << absl::StrFormat("| all | %s | %d/%d | %.2e | %.2e | %d/%d | %.0f |\n", name, s->converged,
                                 s->runs, Median(s->errors),
                                 *std::max_element(s->errors.begin(), s->errors.end()), s->within_1e3, s->runs,
                                 Median(s->analyses));
  }
  return 0;
}

}  // namespace
}  // namespace mbopt::slp::testing

int main(int argc, char** argv) { return mbopt::slp::testing::Main(argc, argv); }
