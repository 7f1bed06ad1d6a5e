#include "server/jobs/pareto_grid_run.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/jobs/analysis_gradients.h"
#include "spec/pareto.h"

namespace mbopt::jobs {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kAnchors = spec::kParetoAnchorsOfThree;

}  // namespace

absl::StatusOr<std::unique_ptr<ParetoGridRun>> ParetoGridRun::Create(ParetoGridSetup setup,
                                                                     LpSolverFactory make_lp_solver) {
  if (setup.levels < spec::kMinParetoGridLevels || setup.levels > spec::kMaxParetoGridLevels) {
    return absl::InvalidArgumentError(absl::StrFormat("a front of three objectives has %d to %d levels, got %d",
                                                      spec::kMinParetoGridLevels, spec::kMaxParetoGridLevels,
                                                      setup.levels));
  }
  if (!make_lp_solver) return absl::InvalidArgumentError("a Pareto front needs an LP solver for each of its points");
  if (setup.traded_constraints[0] == setup.traded_constraints[1]) {
    return absl::InvalidArgumentError("a front of three objectives trades two different constraints");
  }
  std::array<std::vector<int>, 2> traded;
  for (int g = 0; g < 2; ++g) {
    for (std::size_t h = 0; h < setup.row_constraints.size(); ++h) {
      if (setup.row_constraints[h] == setup.traded_constraints[static_cast<std::size_t>(g)]) {
        traded[static_cast<std::size_t>(g)].push_back(static_cast<int>(h));
      }
    }
    const std::vector<int>& rows = traded[static_cast<std::size_t>(g)];
    if (rows.empty()) {
      return absl::InvalidArgumentError(absl::StrCat("the traded constraint ",
                                                     setup.traded_constraints[static_cast<std::size_t>(g)],
                                                     " has no constraint rows"));
    }
    if (absl::Status shared = CheckTradedRowsShareLimit(setup.problem, rows); !shared.ok()) return shared;
  }
  std::unique_ptr<ParetoGridRun> run(new ParetoGridRun(std::move(setup), std::move(make_lp_solver)));
  run->traded_rows_ = std::move(traded);
  for (std::size_t g = 0; g < 2; ++g) {
    run->traded_scale_[g] = run->setup_.problem.constraint_scales[run->traded_rows_[g][0]];
  }
  run->StartRuns();
  return run;
}

ParetoGridRun::ParetoGridRun(ParetoGridSetup setup, LpSolverFactory make_lp_solver)
    : PointFrontRun(std::move(setup), std::move(make_lp_solver)) {
  const std::vector<int> parents = spec::ParetoGridWarmStartParents(setup_.levels);
  points_.resize(parents.size());
  for (std::size_t k = 0; k < points_.size(); ++k) {
    points_[k].parent = parents[k];
    points_[k].level_si = {kNaN, kNaN};
    points_[k].objective = k == 1 ? 0 : k == 2 ? 1 : kStudyObjective;
  }
}

int ParetoGridRun::TradedGroup(int row) const {
  const int c = setup_.row_constraints[static_cast<std::size_t>(row)];
  for (int g = 0; g < 2; ++g) {
    if (c == setup_.traded_constraints[static_cast<std::size_t>(g)]) return g;
  }
  return -1;
}

void ParetoGridRun::StartRuns() {
  for (int k = 0; k < kAnchors; ++k) {
    Point& anchor = points_[static_cast<std::size_t>(k)];
    if (anchor.run == nullptr && !anchor.ended) Start(k, setup_.problem.initial);
  }
  for (int k = 0; k < kAnchors; ++k) {
    if (!points_[static_cast<std::size_t>(k)].ended) return;
  }
  // The anchors' values: anchor a's F2 and F3 (a = 0 the objective's own
  // optimum, 1 and 2 those of F2 and F3).
  auto value = [&](int a, int g) {
    return g == 0 ? points_[static_cast<std::size_t>(a)].record.pareto_value_si
                  : points_[static_cast<std::size_t>(a)].record.pareto_value3_si;
  };
  std::string reason;
  std::array<double, 2> upper = {kNaN, kNaN}, lower = {kNaN, kNaN};
  for (int a = 0; a < kAnchors && reason.empty(); ++a) {
    if (!points_[static_cast<std::size_t>(a)].usable) {
      reason = absl::StrCat("the grid has no box to span: point ", a + 1, " (an anchor) has no feasible result");
    }
  }
  for (int g = 0; g < 2 && reason.empty(); ++g) {
    // The least value is the objective's own anchor's; the largest that
    // matters is the largest the other two anchors have.
    const int own = g + 1;
    lower[static_cast<std::size_t>(g)] = value(own, g);
    upper[static_cast<std::size_t>(g)] = std::max(value(0, g), value(own == 1 ? 2 : 1, g));
    if (!(upper[static_cast<std::size_t>(g)] > lower[static_cast<std::size_t>(g)])) {
      reason = absl::StrFormat(
          "the objectives do not conflict: objective %d's least value (%.9g) is no less than its value at the "
          "other anchors (%.9g at most)",
          g + 2, lower[static_cast<std::size_t>(g)], upper[static_cast<std::size_t>(g)]);
    }
  }
  const int n = setup_.levels;
  for (int k = kAnchors; k < static_cast<int>(points_.size()); ++k) {
    Point& point = points_[static_cast<std::size_t>(k)];
    if (point.ended || point.run != nullptr) continue;
    const int i = (k - kAnchors) / n, j = (k - kAnchors) % n;
    if (reason.empty()) {
      point.level_si = {spec::ParetoGridLevel(i, n, upper[0], lower[0]), spec::ParetoGridLevel(j, n, upper[1], lower[1])};
    }
    if (!reason.empty()) {
      EndWithoutRun(k, reason);
      continue;
    }
    const Point& parent = points_[static_cast<std::size_t>(point.parent)];
    if (!parent.ended) continue;
    Start(k, parent.record.x0);
  }
}

void ParetoGridRun::Start(int k, const Eigen::VectorXd& initial) {
  Point& point = points_[static_cast<std::size_t>(k)];
  const slp::ProblemSpec& study = setup_.problem;
  slp::ProblemSpec problem = study;
  slp::SlpOptions options = setup_.options;
  problem.initial = initial;
  const bool anchor = k < kAnchors;
  point.rows.clear();
  for (int h = 0; h < study.num_constraints(); ++h) {
    if (!anchor || TradedGroup(h) < 0) point.rows.push_back(h);
  }
  if (anchor) {
    KeepStudyRows(study, point.rows, &problem);
  } else {
    for (std::size_t g = 0; g < 2; ++g) {
      for (int h : traded_rows_[g]) {
        problem.constraint_limits[h] = point.level_si[g];
        problem.constraint_scales[h] = LimitScale(point.level_si[g]);
      }
    }
  }
  if (point.objective != kStudyObjective) {
    MinimizeTradedRows(static_cast<int>(traded_rows_[static_cast<std::size_t>(point.objective)].size()), &problem,
                       &options);
  }
  StartRun(k, std::move(problem), options);
}

void ParetoGridRun::SetFrontFields(const Point& point, const Analysed* values, slp::CycleRecord* r) const {
  r->pareto_three = true;
  r->pareto_level_si = point.level_si[0];
  r->pareto_level3_si = point.level_si[1];
  r->pareto_value_si = values == nullptr ? kNaN : values->traded_si[0];
  r->pareto_value3_si = values == nullptr ? kNaN : values->traded_si[1];
}

void ParetoGridRun::AnalyseTraded(const AnalysisRecord& record, Analysed* a) const {
  for (std::size_t g = 0; g < 2; ++g) {
    double largest = -std::numeric_limits<double>::infinity();
    for (int h : traded_rows_[g]) largest = std::max(largest, record.constraint_values[static_cast<std::size_t>(h)]);
    a->traded_si[g] = largest;
  }
}

void ParetoGridRun::TranslateResult(const Point& point, const AnalysisRecord& record,
                                    slp::AnalysisResult* out) const {
  slp::AnalysisResult& result = *out;
  const std::vector<double>& values = record.constraint_values;
  if (point.objective == kStudyObjective) {
    result.objective_terms = Eigen::Map<const Eigen::VectorXd>(record.objective_terms.data(),
                                                               static_cast<Eigen::Index>(record.objective_terms.size()));
  } else {
    const auto g = static_cast<std::size_t>(point.objective);
    result.objective_terms.resize(static_cast<Eigen::Index>(traded_rows_[g].size()));
    for (std::size_t j = 0; j < traded_rows_[g].size(); ++j) {
      result.objective_terms[static_cast<Eigen::Index>(j)] =
          values[static_cast<std::size_t>(traded_rows_[g][j])] / traded_scale_[g];
    }
  }
  result.constraint_values.resize(static_cast<Eigen::Index>(point.rows.size()));
  for (std::size_t j = 0; j < point.rows.size(); ++j) {
    result.constraint_values[static_cast<Eigen::Index>(j)] = values[static_cast<std::size_t>(point.rows[j])];
  }
  if (!record.objective_gradients.empty()) {
    const std::size_t n = static_cast<std::size_t>(setup_.problem.num_variables());
    std::vector<double> objective_gradients;
    if (point.objective == kStudyObjective) {
      objective_gradients = record.objective_gradients;
    } else {
      const auto g = static_cast<std::size_t>(point.objective);
      for (int h : traded_rows_[g]) AppendRow(record.constraint_gradients, n, h, 1.0 / traded_scale_[g], &objective_gradients);
    }
    std::vector<double> constraint_gradients;
    constraint_gradients.reserve(point.rows.size() * n);
    for (int h : point.rows) AppendRow(record.constraint_gradients, n, h, 1.0, &constraint_gradients);
    AttachGradients(point.problem, objective_gradients, constraint_gradients, &result);
  }
}

}  // namespace mbopt::jobs
