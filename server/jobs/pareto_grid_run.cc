#include "server/jobs/pareto_grid_run.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "common/check.h"
#include "server/jobs/analysis_gradients.h"
#include "spec/pareto.h"

namespace mbopt::jobs {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kAnchors = spec::kParetoAnchorsOfThree;

bool SameBits(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && (a.size() == 0 || std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0);
}

// Row `row` of a row-major matrix of `columns` columns, times `factor`,
// appended to `out`.
void AppendRow(const std::vector<double>& matrix, std::size_t columns, int row, double factor,
               std::vector<double>* out) {
  const std::size_t first = static_cast<std::size_t>(row) * columns;
  for (std::size_t c = 0; c < columns; ++c) out->push_back(matrix[first + c] * factor);
}

// A limit's scale as the study's layout scales one (spec/layout.cc), so a
// single run with this limit written in the study is the same problem.
double ScaleOf(double limit) { return limit != 0.0 ? std::abs(limit) : 1.0; }

}  // namespace

absl::StatusOr<std::unique_ptr<ParetoGridRun>> ParetoGridRun::Create(
    ParetoGridSetup setup, std::function<std::unique_ptr<lp::LpSolver>()> make_lp_solver) {
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
    const slp::ProblemSpec& p = setup.problem;
    for (int h : rows) {
      if (p.constraint_limits[h] != p.constraint_limits[rows[0]] || p.constraint_scales[h] != p.constraint_scales[rows[0]]) {
        return absl::InvalidArgumentError(absl::StrCat("the traded constraint's rows \"", p.constraint_names[rows[0]],
                                                       "\" and \"", p.constraint_names[h],
                                                       "\" have different limits; a front moves one limit"));
      }
    }
  }
  std::unique_ptr<ParetoGridRun> run(new ParetoGridRun(std::move(setup), std::move(make_lp_solver)));
  run->traded_rows_ = std::move(traded);
  for (std::size_t g = 0; g < 2; ++g) {
    run->traded_scale_[g] = run->setup_.problem.constraint_scales[run->traded_rows_[g][0]];
  }
  run->StartRuns();
  return run;
}

ParetoGridRun::ParetoGridRun(ParetoGridSetup setup, std::function<std::unique_ptr<lp::LpSolver>()> make_lp_solver)
    : setup_(std::move(setup)), make_lp_solver_(std::move(make_lp_solver)) {
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
    problem.constraint_names.clear();
    problem.constraint_limits.resize(static_cast<Eigen::Index>(point.rows.size()));
    problem.constraint_scales.resize(static_cast<Eigen::Index>(point.rows.size()));
    for (std::size_t j = 0; j < point.rows.size(); ++j) {
      const int h = point.rows[j];
      problem.constraint_names.push_back(study.constraint_names[static_cast<std::size_t>(h)]);
      problem.constraint_limits[static_cast<Eigen::Index>(j)] = study.constraint_limits[h];
      problem.constraint_scales[static_cast<Eigen::Index>(j)] = study.constraint_scales[h];
    }
  } else {
    for (std::size_t g = 0; g < 2; ++g) {
      for (int h : traded_rows_[g]) {
        problem.constraint_limits[h] = point.level_si[g];
        problem.constraint_scales[h] = ScaleOf(point.level_si[g]);
      }
    }
  }
  if (point.objective != kStudyObjective) {
    // F2 or F3, in the study's scale of its rows so that F is of order one
    // near the constraint's limit.
    problem.num_objective_terms = static_cast<int>(traded_rows_[static_cast<std::size_t>(point.objective)].size());
    problem.objective_form = problem.num_objective_terms == 1 ? slp::ObjectiveForm::kScalar : slp::ObjectiveForm::kMinMax;
    problem.objective_group_sizes.clear();
    options.objective_target.reset();  // the study's target is for its own objective
  }
  const absl::Status valid = problem.Validate();
  MBOPT_CHECK(valid.ok(), absl::StrCat("Pareto point ", k + 1, ": ", valid.message()).c_str());
  point.problem = problem;
  point.run = std::make_unique<slp::SlpOptimizer>(std::move(problem), options, make_lp_solver_());
}

void ParetoGridRun::EndWithoutRun(int k, const std::string& reason) {
  Point& point = points_[static_cast<std::size_t>(k)];
  point.ended = true;
  point.usable = false;
  slp::CycleRecord& r = point.record;
  r.design_set = true;
  r.pareto = true;
  r.pareto_three = true;
  r.cycle = k + 1;
  r.x0 = r.x_trial = setup_.problem.initial;
  r.accepted = false;
  r.rejection_reason = reason;
  r.objective_x0 = r.objective_trial = r.objective_predicted = kNaN;
  r.max_violation_x0 = r.max_violation_trial = kNaN;
  r.objective_error = r.max_approximation_error = r.optimality_residual = kNaN;
  r.constraint_violations.assign(static_cast<std::size_t>(setup_.num_constraints), kNaN);
  r.pareto_level_si = point.level_si[0];
  r.pareto_level3_si = point.level_si[1];
  r.pareto_value_si = r.pareto_value3_si = kNaN;
  r.pareto_state = "not_run";
}

void ParetoGridRun::End(int k) {
  Point& point = points_[static_cast<std::size_t>(k)];
  const slp::SlpOptimizer& run = *point.run;
  point.ended = true;
  const slp::DesignPoint best = run.best_design();
  const Analysed* values = nullptr;
  for (auto it = point.analysed.rbegin(); it != point.analysed.rend() && values == nullptr; ++it) {
    if (SameBits(it->x, best.x)) values = &*it;
  }
  slp::CycleRecord& r = point.record;
  r.design_set = true;
  r.pareto = true;
  r.pareto_three = true;
  r.cycle = k + 1;
  r.x0 = r.x_trial = best.x;
  r.objective_predicted = r.objective_error = r.max_approximation_error = r.optimality_residual = kNaN;
  r.pareto_level_si = point.level_si[0];
  r.pareto_level3_si = point.level_si[1];
  r.pareto_state = slp::RunStateName(run.state());
  r.pareto_cycles = run.cycles_completed();
  r.pareto_analyses = run.analyses_used();
  if (values == nullptr) {
    r.objective_x0 = r.objective_trial = kNaN;
    r.max_violation_x0 = r.max_violation_trial = kNaN;
    r.constraint_violations.assign(static_cast<std::size_t>(setup_.num_constraints), kNaN);
    r.pareto_value_si = r.pareto_value3_si = kNaN;
  } else {
    r.objective_x0 = r.objective_trial = values->objective;
    r.max_violation_x0 = r.max_violation_trial = best.max_violation;
    r.constraint_violations = values->violations;
    r.pareto_value_si = values->traded_si[0];
    r.pareto_value3_si = values->traded_si[1];
  }
  point.usable = values != nullptr && run.state() != slp::RunState::kFailed &&
                 best.max_violation <= setup_.options.convergence_violation_tolerance;
  r.accepted = point.usable;
  if (!point.usable) {
    // A grid point whose levels no design meets (the box of its bounds
    // misses the front's reach) ends here: its best design still violates.
    r.rejection_reason = run.state() == slp::RunState::kFailed || values == nullptr
                             ? absl::StrCat("the run failed: ", run.end_reason())
                             : absl::StrFormat("no feasible design: maxg %.4g at the best design", best.max_violation);
  }
}

slp::CycleRecord ParetoGridRun::RunCycle(const Point& point, int k, slp::CycleRecord record) const {
  record.pareto_point = k + 1;
  auto study_row = [&](int h) {
    if (h < 0 || static_cast<std::size_t>(h) >= point.rows.size()) return h;
    return point.rows[static_cast<std::size_t>(h)];
  };
  record.worst_constraint_trial = study_row(record.worst_constraint_trial);
  record.worst_approximation_row = study_row(record.worst_approximation_row);
  return record;
}

ParetoGridRun::Analysed ParetoGridRun::Analyse(const AnalysisRecord& record) const {
  const slp::ProblemSpec& p = setup_.problem;
  Analysed a;
  a.x = Eigen::Map<const Eigen::VectorXd>(record.x_scaled.data(), static_cast<Eigen::Index>(record.x_scaled.size()));
  const Eigen::Map<const Eigen::VectorXd> terms(record.objective_terms.data(),
                                                static_cast<Eigen::Index>(record.objective_terms.size()));
  a.objective = slp::ObjectiveValue(p, terms);
  for (std::size_t g = 0; g < 2; ++g) {
    double largest = -std::numeric_limits<double>::infinity();
    for (int h : traded_rows_[g]) largest = std::max(largest, record.constraint_values[static_cast<std::size_t>(h)]);
    a.traded_si[g] = largest;
  }
  a.violations.assign(static_cast<std::size_t>(setup_.num_constraints), kNaN);
  for (std::size_t h = 0; h < record.constraint_values.size(); ++h) {
    const double g = record.constraint_values[h];
    const auto row = static_cast<Eigen::Index>(h);
    const int c = setup_.row_constraints[h];
    if (c >= 0 && c < setup_.num_constraints) {
      const double normalized = (g - p.constraint_limits[row]) / p.constraint_scales[row];
      double& of_constraint = a.violations[static_cast<std::size_t>(c)];
      of_constraint = std::isnan(of_constraint) ? normalized : std::max(of_constraint, normalized);
    }
  }
  return a;
}

slp::AnalysisResult ParetoGridRun::ResultFor(const Point& point, const AnalysisRecord& record) const {
  slp::AnalysisResult result;
  result.request_id = record.request_id % kRequestStride;
  result.outcome = record.ok() ? slp::AnalysisOutcome::kOk : slp::AnalysisOutcome::kFailed;
  result.failure_reason = record.failure.reason;
  if (!record.ok()) return result;
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
  return result;
}

std::vector<slp::AnalysisRequest> ParetoGridRun::PendingRequests() const { return PendingRequestsOfPoints(points_); }

bool ParetoGridRun::IsPending(std::int64_t request_id) const { return IsPendingInPoints(points_, request_id); }

absl::Status ParetoGridRun::Submit(const AnalysisRecord& record) {
  if (!IsPending(record.request_id)) {
    return absl::InvalidArgumentError(absl::StrCat("request ", record.request_id, " is not pending in the front"));
  }
  const int k = static_cast<int>(record.request_id / kRequestStride);
  Point& point = points_[static_cast<std::size_t>(k)];
  ++analyses_;
  if (record.ok()) point.analysed.push_back(Analyse(record));
  const absl::Status submitted = point.run->SubmitResult(ResultFor(point, record));
  if (!submitted.ok()) return submitted;
  for (slp::CycleRecord& cycle : point.run->TakeNewRecords()) {
    if (log_run_cycles_) point.cycles.push_back(RunCycle(point, k, std::move(cycle)));
  }
  if (point.run->state() != slp::RunState::kRunning) {
    End(k);
    StartRuns();
  }
  EmitEndedPointsInOrder(&points_, &emitted_, &new_records_);
  return absl::OkStatus();
}

std::vector<slp::CycleRecord> ParetoGridRun::TakeNewRecords() { return std::exchange(new_records_, {}); }

}  // namespace mbopt::jobs
