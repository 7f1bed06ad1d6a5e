// Hard cases for the SLP core where the physics is not the point: analytic
// evaluators run through slp::RunToCompletion with the CLP LP solver. Each
// test says what it checks and with what tolerance. Every run must end in a
// named state with finite numbers; none may crash, hang or end in NaN.
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "server/lp/make_clp_lp_solver.h"
#include "tests/slp_testing/drive_optimizer.h"
#include "server/slp/slp_optimizer.h"
#include "tests/hardcase/analytic_problems.h"

namespace mbopt::hardcase {
namespace {

constexpr double kPi = 3.14159265358979323846;

// One line per run for docs/hardcases.md.
void Report(const std::string& name, const slp::RunOutcome& out) {
  std::cout << "[hardcase] " << name << ": state " << slp::RunStateName(out.state) << ", F "
            << out.objective << ", maxg " << out.max_violation << ", cycles " << out.cycles
            << ", analyses " << out.analyses << "\n";
}

slp::RunOutcome RunSlp(slp::ProblemSpec spec, const slp::SlpOptions& options, const slp::Evaluator& evaluate) {
  EXPECT_TRUE(spec.Validate().ok()) << spec.Validate();
  EXPECT_TRUE(options.Validate().ok()) << options.Validate();
  slp::SlpOptimizer optimizer(std::move(spec), options, lp::MakeClpLpSolver());
  slp::RunToCompletionOptions guard;
  guard.max_analyses = 20'000;  // a hang shows up as ResourceExhausted
  absl::StatusOr<slp::RunOutcome> out = slp::RunToCompletion(optimizer, evaluate, guard);
  EXPECT_TRUE(out.ok()) << out.status();
  return out.ok() ? *out : slp::RunOutcome{};
}

void ExpectFiniteEnd(const slp::RunOutcome& out) {
  EXPECT_NE(out.state, slp::RunState::kRunning);
  EXPECT_TRUE(std::isfinite(out.objective));
  EXPECT_TRUE(std::isfinite(out.max_violation));
  EXPECT_TRUE(out.design.allFinite());
}

// ---------------------------------------------------------------------------
// Design variables of natural size 1e-6 and 1e6 in one problem: HS 43 with
// physical p = (1e-6 u1, 1e6 u2, u3, u4). Checks: with the study's scale
// factors (1e-6, 1e6, 1, 1) the scaled variables are O(1) and the method
// reaches F = -44; with scale 1 (the core sees p itself, bounds 1e-5 and 1e7)
// it still converges to the same optimum, because move limits and
// finite-difference steps are relative to each variable and its range.
// Tolerance: 0.5 % of |F*| (the convergence test stops at a 0.5 % change)
// and 0.15 in each u: F is quadratic about its constrained minimum, so an
// objective error dF allows a design error of order sqrt(dF / curvature),
// sqrt(0.22 / 2) = 0.33 at worst; 0.15 still catches a wrong vertex.
constexpr double kScalingObjectiveTolerance = 0.005 * 44.0;
constexpr double kHs43DesignTolerance = 0.15;

slp::RunOutcome RunHs43WithScales(const Eigen::Vector4d& natural_size, const Eigen::Vector4d& study_scale) {
  // Scaled x -> physical p = study_scale .* x -> u = p ./ natural_size.
  const Eigen::Vector4d x_per_u = natural_size.cwiseQuotient(study_scale);
  const Eigen::Vector4d u0(1.0, 1.0, 1.0, 1.0);
  slp::ProblemSpec spec = MakeSpec(-10.0 * x_per_u, 10.0 * x_per_u, u0.cwiseProduct(x_per_u), Hs43Limits(),
                                   Hs43Limits());
  const Values values = [x_per_u](const Eigen::VectorXd& x, Eigen::VectorXd* f, Eigen::VectorXd* g) {
    Hs43(x.cwiseQuotient(x_per_u), f, g);
  };
  return RunSlp(spec, slp::SlpOptions{}, [&values](const slp::AnalysisRequest& r) { return Evaluate(values, r); });
}

TEST(HardcaseScaling, VariablesOfSize1eMinus6And1e6ConvergeWhenScaled) {
  const Eigen::Vector4d natural(1e-6, 1e6, 1.0, 1.0);
  const slp::RunOutcome out = RunHs43WithScales(natural, natural);
  Report("scaling 1e-6/1e6, study scales", out);
  ExpectFiniteEnd(out);
  EXPECT_EQ(out.state, slp::RunState::kConverged);
  EXPECT_NEAR(out.objective, kHs43Optimum, kScalingObjectiveTolerance);
  EXPECT_LE(out.max_violation, 0.0);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(out.design[i], Hs43OptimumDesign()[i], kHs43DesignTolerance) << i;
}

TEST(HardcaseScaling, VariablesOfSize1eMinus6And1e6ConvergeUnscaled) {
  const Eigen::Vector4d natural(1e-6, 1e6, 1.0, 1.0);
  const slp::RunOutcome out = RunHs43WithScales(natural, Eigen::Vector4d::Ones());
  Report("scaling 1e-6/1e6, scale 1", out);
  ExpectFiniteEnd(out);
  EXPECT_EQ(out.state, slp::RunState::kConverged);
  EXPECT_NEAR(out.objective, kHs43Optimum, kScalingObjectiveTolerance);
  EXPECT_LE(out.max_violation, 0.0);
  const Eigen::Vector4d u = out.design.cwiseQuotient(natural);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(u[i], Hs43OptimumDesign()[i], kHs43DesignTolerance) << i;
}

// ---------------------------------------------------------------------------
// Degenerate LPs with 10 000 rows: g_i(x) = x1 cos t_i + x2 sin t_i +
// 0.1 (x1^2 + x2^2) <= 1 at 5000 angles t_i in [0, pi/2], every row written
// twice (exact duplicates; neighbours are nearly parallel), screening off so
// that the LP sees all 10 000 rows. Minimize -(x1 + x2): by symmetry the
// optimum is x1 = x2 = a with a sqrt(2) + 0.2 a^2 = 1 (t = pi/4 active),
// a = (sqrt(2.8) - sqrt(2)) / 0.4. Checks: every LP solves optimal, the run
// converges, F within 0.5 % of -2a.
constexpr int kDenseAngles = 5000;

TEST(HardcaseDegenerateLp, TenThousandDuplicatedNearlyParallelRowsSolveAndConverge) {
  const double a = (std::sqrt(2.8) - std::sqrt(2.0)) / 0.4;
  const int m = 2 * kDenseAngles;
  slp::ProblemSpec spec = MakeSpec(Eigen::Vector2d::Zero(), Eigen::Vector2d::Constant(2.0),
                                   Eigen::Vector2d::Constant(0.2), Eigen::VectorXd::Ones(m),
                                   Eigen::VectorXd::Ones(m));
  Eigen::VectorXd cos_t(kDenseAngles), sin_t(kDenseAngles);
  for (int i = 0; i < kDenseAngles; ++i) {
    const double t = 0.5 * kPi * i / (kDenseAngles - 1);
    cos_t[i] = std::cos(t);
    sin_t[i] = std::sin(t);
  }
  const Values values = [&](const Eigen::VectorXd& x, Eigen::VectorXd* f, Eigen::VectorXd* g) {
    *f = Eigen::VectorXd::Constant(1, -(x[0] + x[1]));
    const Eigen::VectorXd once = x[0] * cos_t + x[1] * sin_t +
                                 Eigen::VectorXd::Constant(kDenseAngles, 0.1 * x.squaredNorm());
    g->resize(m);
    for (int i = 0; i < kDenseAngles; ++i) (*g)[2 * i] = (*g)[2 * i + 1] = once[i];
  };
  slp::SlpOptions options;
  options.screening_threshold = -1e6;  // keep every row in every LP
  const slp::RunOutcome out =
      RunSlp(spec, options, [&values](const slp::AnalysisRequest& r) { return Evaluate(values, r); });
  Report("10000 duplicated rows", out);
  ExpectFiniteEnd(out);
  EXPECT_EQ(out.state, slp::RunState::kConverged);
  EXPECT_NEAR(out.objective, -2.0 * a, 0.005 * 2.0 * a);
  EXPECT_LE(out.max_violation, 0.0);
  int max_rows = 0;
  for (const slp::CycleRecord& r : out.records) {
    EXPECT_EQ(r.lp_status, "optimal") << "cycle " << r.cycle << " attempt " << r.attempt;
    max_rows = std::max(max_rows, r.rows_screened_in);
  }
  std::cout << "[hardcase] 10000 duplicated rows: largest LP has " << max_rows << " constraint rows\n";
  EXPECT_EQ(max_rows, m);
}

// The same family straight to CLP: maximize x1 + x2 subject to the 10 000
// tangent rows x1 cos t_i + x2 sin t_i <= 1 (duplicated, nearly parallel).
// The polygon's optimum exceeds sqrt(2) by O(dt^2) = 1e-7 at most.
TEST(HardcaseDegenerateLp, ClpSolvesTenThousandTangentRows) {
  lp::LinearProgram program;
  program.objective = Eigen::Vector2d(-1.0, -1.0);
  program.column_lower = Eigen::Vector2d::Zero();
  program.column_upper = Eigen::Vector2d::Constant(10.0);
  const int m = 2 * kDenseAngles;
  program.rows.resize(m, 2);
  program.row_lower = Eigen::VectorXd::Constant(m, -std::numeric_limits<double>::infinity());
  program.row_upper = Eigen::VectorXd::Ones(m);
  for (int i = 0; i < kDenseAngles; ++i) {
    const double t = 0.5 * kPi * i / (kDenseAngles - 1);
    program.rows.row(2 * i) << std::cos(t), std::sin(t);
    program.rows.row(2 * i + 1) << std::cos(t), std::sin(t);
  }
  const lp::LpSolution solution = lp::MakeClpLpSolver()->Solve(program);
  ASSERT_EQ(solution.status, lp::LpStatus::kOptimal) << solution.message;
  std::cout << "[hardcase] CLP 10000 tangent rows: " << solution.iterations << " iterations, objective "
            << -solution.objective_value << "\n";
  EXPECT_NEAR(-solution.objective_value, std::sqrt(2.0), 1e-6);
}

// ---------------------------------------------------------------------------
// Fault injection: HS 43 where 10 % of the designs (a seeded hash of the
// design's bits; the start design exempt, since without x0 there is no run)
// fail, half of them as kFailed and half returning NaN values; eight seeds.
// Checks, for every seed: the run converges to the optimum within 0.5 % of
// |F*| and 0.15 per variable (kHs43DesignTolerance); no accepted trial is a
// design whose analysis failed. Over all seeds, failures hit trial points
// and finite-difference perturbations both (so both paths were exercised).
constexpr int kFaultSeeds = 8;

TEST(HardcaseFaultInjection, TenPercentFailedOrNanAnalysesStillReachTheOptimum) {
  const Eigen::Vector4d u0(1.0, 1.0, 1.0, 1.0);
  const slp::ProblemSpec spec = MakeSpec(Eigen::Vector4d::Constant(-10.0), Eigen::Vector4d::Constant(10.0), u0,
                                         Hs43Limits(), Hs43Limits());
  const slp::RunOutcome clean =
      RunSlp(spec, slp::SlpOptions{}, [](const slp::AnalysisRequest& r) { return Evaluate(Hs43, r); });
  Report("fault injection, reference run", clean);

  int failed_trials = 0, failed_perturbations = 0;
  for (std::uint64_t seed = 1; seed <= kFaultSeeds; ++seed) {
    std::vector<Eigen::VectorXd> failed_designs;
    int nan_results = 0;
    const slp::Evaluator faulty = [&](const slp::AnalysisRequest& request) {
      slp::AnalysisResult result = Evaluate(Hs43, request);
      const std::uint64_t h = DesignHash(request.x, seed);
      if (request.id == 0 || h % 10 != 0) return result;
      failed_designs.push_back(request.x);
      if (request.purpose == slp::RequestPurpose::kTrial) ++failed_trials;
      if (request.purpose == slp::RequestPurpose::kPerturbation) ++failed_perturbations;
      if ((h / 10) % 2 == 0) {
        result.outcome = slp::AnalysisOutcome::kFailed;
        result.failure_reason = "injected failure";
      } else {
        result.objective_terms.setConstant(std::numeric_limits<double>::quiet_NaN());
        result.constraint_values[0] = std::numeric_limits<double>::quiet_NaN();
        ++nan_results;
      }
      return result;
    };
    const slp::RunOutcome out = RunSlp(spec, slp::SlpOptions{}, faulty);
    Report("fault injection seed " + std::to_string(seed), out);
    std::cout << "[hardcase]   " << failed_designs.size() << " failed analyses (" << nan_results << " NaN)\n";
    ExpectFiniteEnd(out);
    EXPECT_EQ(out.state, slp::RunState::kConverged) << "seed " << seed;
    EXPECT_NEAR(out.objective, clean.objective, kScalingObjectiveTolerance) << "seed " << seed;
    EXPECT_NEAR(out.objective, kHs43Optimum, kScalingObjectiveTolerance) << "seed " << seed;
    for (int i = 0; i < 4; ++i) {
      EXPECT_NEAR(out.design[i], Hs43OptimumDesign()[i], kHs43DesignTolerance) << "seed " << seed << " x" << i;
    }
    for (const slp::CycleRecord& r : out.records) {
      if (!r.accepted) continue;
      EXPECT_TRUE(std::isfinite(r.objective_trial)) << "seed " << seed << " cycle " << r.cycle;
      for (const Eigen::VectorXd& bad : failed_designs) {
        EXPECT_FALSE(bad == r.x_trial) << "seed " << seed << " cycle " << r.cycle << " accepted a failed design";
      }
    }
  }
  std::cout << "[hardcase] fault injection: " << failed_trials << " failed trials, " << failed_perturbations
            << " failed perturbations over " << kFaultSeeds << " seeds\n";
  EXPECT_GT(failed_trials, 0);
  EXPECT_GT(failed_perturbations, 0);
}

// ---------------------------------------------------------------------------
// A min-max objective whose maximum jumps between instants: F(x) = max over
// t in a 101-point grid on [0, 1] of |sin(pi t) - x1 t - x2| (terms f and -f
// per instant). As x moves, the peak jumps between t = 0, t = 1 and the
// interior. The best uniform line approximation of sin(pi t) is x = (0, 0.5)
// with F = 0.5 (equioscillation at t = 0, 0.5, 1, all on the grid). Checks:
// converged, F within 0.5 % of 0.5, x within 0.02.
TEST(HardcaseMinMax, PeakInstantSwitchingConvergesToChebyshevOptimum) {
  constexpr int kInstants = 101;
  slp::ProblemSpec spec = MakeSpec(Eigen::Vector2d::Constant(-2.0), Eigen::Vector2d::Constant(2.0),
                                   Eigen::Vector2d(1.0, 0.0), Eigen::VectorXd(0), Eigen::VectorXd(0));
  spec.objective_form = slp::ObjectiveForm::kMinMax;
  spec.num_objective_terms = 2 * kInstants;
  const Values values = [](const Eigen::VectorXd& x, Eigen::VectorXd* f, Eigen::VectorXd* g) {
    f->resize(2 * kInstants);
    for (int i = 0; i < kInstants; ++i) {
      const double t = static_cast<double>(i) / (kInstants - 1);
      const double e = std::sin(kPi * t) - x[0] * t - x[1];
      (*f)[2 * i] = e;
      (*f)[2 * i + 1] = -e;
    }
    g->resize(0);
  };
  const slp::RunOutcome out =
      RunSlp(spec, slp::SlpOptions{}, [&values](const slp::AnalysisRequest& r) { return Evaluate(values, r); });
  Report("min-max switching peak", out);
  // The instant of the peak at each accepted design: it must have jumped.
  std::set<int> peak_instants;
  for (const slp::CycleRecord& r : out.records) {
    if (!r.accepted) continue;
    Eigen::VectorXd f, g;
    values(r.x_trial, &f, &g);
    Eigen::Index worst = 0;
    f.maxCoeff(&worst);
    peak_instants.insert(static_cast<int>(worst / 2));
  }
  std::cout << "[hardcase] min-max: peak at " << peak_instants.size() << " different instants over the run\n";
  EXPECT_GE(peak_instants.size(), 2u);
  ExpectFiniteEnd(out);
  EXPECT_EQ(out.state, slp::RunState::kConverged);
  EXPECT_NEAR(out.objective, 0.5, 0.005 * 0.5);
  EXPECT_NEAR(out.design[0], 0.0, 0.02);
  EXPECT_NEAR(out.design[1], 0.5, 0.02);
}

}  // namespace
}  // namespace mbopt::hardcase
