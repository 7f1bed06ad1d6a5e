#include "server/jobs/pareto_run.h"

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

bool SameBits(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && (a.size() == 0 || std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0);
}

// Rows `rows` of a row-major matrix of `columns` columns, each times `factor`.
std::vector<double> PickRows(const std::vector<double>& matrix, std::size_t columns, const std::vector<int>& rows,
                             double factor) {
  std::vector<double> picked;
  picked.reserve(rows.size() * columns);
  for (int row : rows) {
    for (std::size_t c = 0; c < columns; ++c) picked.push_back(matrix[static_cast<std::size_t>(row) * columns + c] * factor);
  }
  return picked;
}

}  // namespace

absl::StatusOr<std::unique_ptr<ParetoRun>> ParetoRun::Create(ParetoSetup setup, LpSolverFactory make_lp_solver) {
  if (setup.points < spec::kMinParetoPoints) {
    return absl::InvalidArgumentError(
        absl::StrFormat("a Pareto front needs at least %d points, got %d", spec::kMinParetoPoints, setup.points));
  }
  if (setup.refine < 0 || setup.refine > setup.points - 1) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "a front of %d points can be refined by 0 to %d points, got %d", setup.points, setup.points - 1, setup.refine));
  }
  if (setup.refine_again < 0 || (setup.refine_again > 0 && setup.refine == 0) ||
      setup.refine_again > setup.points + setup.refine - 1) {
    return absl::InvalidArgumentError(absl::StrFormat(
        "a refined front of %d points can be refined again by 0 to %d points (with refine above 0), got %d",
        setup.points + setup.refine, setup.points + setup.refine - 1, setup.refine_again));
  }
  if (!make_lp_solver) return absl::InvalidArgumentError("a Pareto front needs an LP solver for each of its points");
  std::vector<int> traded;
  for (size_t h = 0; h < setup.row_constraints.size(); ++h) {
    if (setup.row_constraints[h] == setup.traded_constraint) traded.push_back(static_cast<int>(h));
  }
  if (traded.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("the traded constraint ", setup.traded_constraint, " has no constraint rows"));
  }
  if (setup.traded_factors.empty()) setup.traded_factors.assign(traded.size(), 1.0);
  if (setup.traded_factors.size() != traded.size()) {
    return absl::InvalidArgumentError(absl::StrCat("the second objective has ", traded.size(), " rows but ",
                                                   setup.traded_factors.size(), " factors"));
  }
  for (double factor : setup.traded_factors) {
    // Bounding factor * g <= level row by row needs factor > 0; a sum is
    // one row whatever its weights' signs.
    if (!std::isfinite(factor) || (!setup.traded_sum && !(factor > 0))) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "a factor of the second objective's rows is %g; a largest of values needs factors above 0", factor));
    }
  }
  const slp::ProblemSpec& p = setup.problem;
  for (int h : traded) {
    if (p.constraint_limits[h] != p.constraint_limits[traded[0]] ||
        p.constraint_scales[h] != p.constraint_scales[traded[0]]) {
      return absl::InvalidArgumentError(absl::StrCat("the traded constraint's rows \"", p.constraint_names[traded[0]],
                                                     "\" and \"", p.constraint_names[h],
                                                     "\" have different limits; a front moves one limit"));
    }
  }
  std::unique_ptr<ParetoRun> run(new ParetoRun(std::move(setup), std::move(make_lp_solver)));
  run->traded_rows_ = std::move(traded);
  run->traded_scale_ = run->setup_.problem.constraint_scales[run->traded_rows_[0]];
  run->StartRuns();
  return run;
}

ParetoRun::ParetoRun(ParetoSetup setup, LpSolverFactory make_lp_solver)
    : setup_(std::move(setup)), make_lp_solver_(std::move(make_lp_solver)) {
  points_.resize(static_cast<std::size_t>(setup_.points + setup_.refine + setup_.refine_again));
  const std::vector<int> parents = spec::ParetoWarmStartParents(setup_.points);
  for (std::size_t k = 0; k < points_.size(); ++k) {
    points_[k].parent = k < parents.size() ? parents[k] : -1;
    points_[k].level_si = kNaN;
  }
}

bool ParetoRun::IsTraded(int row) const {
  return setup_.row_constraints[static_cast<std::size_t>(row)] == setup_.traded_constraint;
}

double ParetoRun::TradedValue(const std::vector<double>& row_values) const {
  double value = setup_.traded_sum ? 0.0 : -std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < traded_rows_.size(); ++j) {
    const double term = setup_.traded_factors[j] * row_values[static_cast<std::size_t>(traded_rows_[j])];
    value = setup_.traded_sum ? value + term : std::max(value, term);
  }
  return value;
}

std::vector<double> ParetoRun::SumGradient(const std::vector<double>& row_gradients, std::size_t columns) const {
  std::vector<double> gradient(columns, 0.0);
  for (std::size_t j = 0; j < traded_rows_.size(); ++j) {
    const std::size_t first = static_cast<std::size_t>(traded_rows_[j]) * columns;
    for (std::size_t c = 0; c < columns; ++c) gradient[c] += setup_.traded_factors[j] * row_gradients[first + c];
  }
  return gradient;
}

void ParetoRun::StartRuns() {
  const int last = setup_.points - 1;
  for (int k : {0, last}) {
    if (points_[static_cast<std::size_t>(k)].run == nullptr && !points_[static_cast<std::size_t>(k)].ended) {
      Start(k, setup_.problem.initial);
    }
  }
  const Point& first = points_.front();
  const Point& least = points_[static_cast<std::size_t>(last)];
  if (!first.ended || !least.ended) return;
  std::string reason;
  if (!first.usable || !least.usable) {
    reason = absl::StrCat("the front has no end to start from: point ", first.usable ? last + 1 : 1,
                          " (an anchor) has no feasible result");
  } else if (!(first.record.pareto_value_si > least.record.pareto_value_si)) {
    reason = absl::StrFormat(
        "the objectives do not conflict: where the objective is least, the second objective (%.9g) is already "
        "no more than its least value (%.9g)",
        first.record.pareto_value_si, least.record.pareto_value_si);
  }
  for (int k = 1; k < last; ++k) {
    Point& point = points_[static_cast<std::size_t>(k)];
    if (point.ended || point.run != nullptr) continue;
    if (!reason.empty()) {
      EndWithoutRun(k, reason);
      continue;
    }
    const Point& parent = points_[static_cast<std::size_t>(point.parent)];
    if (!parent.ended) continue;
    point.level_si = spec::ParetoLevel(k, setup_.points, first.record.pareto_value_si, least.record.pareto_value_si);
    Start(k, parent.record.x0);
  }
  StartRefinement(static_cast<std::size_t>(setup_.points), setup_.refine);
  StartRefinement(static_cast<std::size_t>(setup_.points + setup_.refine), setup_.refine_again);
}

void ParetoRun::StartRefinement(std::size_t base, int count) {
  if (count <= 0 || points_[base].ended || points_[base].run != nullptr) return;
  for (std::size_t k = 0; k < base; ++k) {
    if (!points_[k].ended) return;
  }
  // The first objective as the runs minimized it (their F), so that the
  // front's shape does not depend on the sign the study reports it with.
  std::vector<spec::FrontPoint> front;
  for (std::size_t k = 0; k < base; ++k) {
    const slp::CycleRecord& r = points_[k].record;
    front.push_back({r.objective_x0, r.pareto_value_si, points_[k].usable});
  }
  const std::vector<spec::RefinementSegment> segments = spec::RefinementSegments(front, count);
  for (std::size_t j = 0; j < static_cast<std::size_t>(count); ++j) {
    const int k = static_cast<int>(base + j);
    Point& point = points_[base + j];
    if (j >= segments.size()) {
      point.level_si = kNaN;
      EndWithoutRun(k, absl::StrFormat("the front of the first %d points has only %d segments to refine",
                                       static_cast<int>(base), static_cast<int>(segments.size())));
      continue;
    }
    const Point& upper = points_[static_cast<std::size_t>(segments[j].from)];
    const Point& lower = points_[static_cast<std::size_t>(segments[j].to)];
    // From the end with the larger value, as a point between starts from
    // the end of its interval nearer point 1: the other end may be the
    // traded constraint's own minimum, where its gradient vanishes and its
    // linearization says nothing of the new level.
    point.parent = segments[j].from;
    point.level_si = 0.5 * (upper.record.pareto_value_si + lower.record.pareto_value_si);
    Start(k, upper.record.x0);
  }
}

void ParetoRun::Start(int k, const Eigen::VectorXd& initial) {
  Point& point = points_[static_cast<std::size_t>(k)];
  const slp::ProblemSpec& study = setup_.problem;
  slp::ProblemSpec problem = study;
  slp::SlpOptions options = setup_.options;
  problem.initial = initial;
  const bool anchor = k == 0 || k == setup_.points - 1;
  // A sum is bounded by one row of its own in place of its terms' rows.
  const bool leaves_out_traded = anchor || setup_.traded_sum;
  point.rows.clear();
  for (int h = 0; h < study.num_constraints(); ++h) {
    if (!leaves_out_traded || !IsTraded(h)) point.rows.push_back(h);
  }
  // An ordinary limit at the level, scaled as the study's layout scales a
  // limit (spec/layout.cc), so a single run with this limit written in
  // the study is the same problem.
  auto scale_of = [](double limit) { return limit != 0.0 ? std::abs(limit) : 1.0; };
  if (!anchor && setup_.traded_sum) point.rows.push_back(kSumRow);
  if (leaves_out_traded) {
    problem.constraint_names.clear();
    problem.constraint_limits.resize(static_cast<Eigen::Index>(point.rows.size()));
    problem.constraint_scales.resize(static_cast<Eigen::Index>(point.rows.size()));
    for (std::size_t j = 0; j < point.rows.size(); ++j) {
      const int h = point.rows[j];
      const auto row = static_cast<Eigen::Index>(j);
      if (h == kSumRow) {
        problem.constraint_names.push_back("second objective");
        problem.constraint_limits[row] = point.level_si;
        problem.constraint_scales[row] = scale_of(point.level_si);
        continue;
      }
      problem.constraint_names.push_back(study.constraint_names[static_cast<std::size_t>(h)]);
      problem.constraint_limits[row] = study.constraint_limits[h];
      problem.constraint_scales[row] = study.constraint_scales[h];
    }
  } else {
    for (std::size_t j = 0; j < traded_rows_.size(); ++j) {
      const double limit = point.level_si / setup_.traded_factors[j];
      problem.constraint_limits[traded_rows_[j]] = limit;
      problem.constraint_scales[traded_rows_[j]] = scale_of(limit);
    }
  }
  if (k == setup_.points - 1) {
    // The second objective, in the study's scale of its rows so that F is
    // of order one near a constraint's limit.
    problem.num_objective_terms = setup_.traded_sum ? 1 : static_cast<int>(traded_rows_.size());
    problem.objective_form = problem.num_objective_terms == 1 ? slp::ObjectiveForm::kScalar : slp::ObjectiveForm::kMinMax;
    problem.objective_group_sizes.clear();
    options.objective_target.reset();  // the study's target is for its own objective
  }
  const absl::Status valid = problem.Validate();
  MBOPT_CHECK(valid.ok(), absl::StrCat("Pareto point ", k + 1, ": ", valid.message()).c_str());
  point.problem = problem;
  point.run = std::make_unique<slp::SlpOptimizer>(std::move(problem), options, make_lp_solver_());
}

void ParetoRun::EndWithoutRun(int k, const std::string& reason) {
  Point& point = points_[static_cast<std::size_t>(k)];
  point.ended = true;
  point.usable = false;
  point.not_run_reason = reason;
  slp::CycleRecord& r = point.record;
  r.design_set = true;
  r.pareto = true;
  r.cycle = k + 1;
  r.x0 = r.x_trial = setup_.problem.initial;
  r.accepted = false;
  r.rejection_reason = reason;
  r.objective_x0 = r.objective_trial = r.objective_predicted = kNaN;
  r.max_violation_x0 = r.max_violation_trial = kNaN;
  r.objective_error = r.max_approximation_error = r.optimality_residual = kNaN;
  r.constraint_violations.assign(static_cast<std::size_t>(setup_.num_constraints), kNaN);
  r.pareto_level_si = point.level_si;
  r.pareto_value_si = kNaN;
  r.pareto_state = "not_run";
}

void ParetoRun::End(int k) {
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
  r.cycle = k + 1;
  r.x0 = r.x_trial = best.x;
  r.objective_predicted = r.objective_error = r.max_approximation_error = r.optimality_residual = kNaN;
  r.pareto_level_si = point.level_si;
  r.pareto_state = slp::RunStateName(run.state());
  r.pareto_cycles = run.cycles_completed();
  r.pareto_analyses = run.analyses_used();
  if (values == nullptr) {
    r.objective_x0 = r.objective_trial = kNaN;
    r.max_violation_x0 = r.max_violation_trial = kNaN;
    r.constraint_violations.assign(static_cast<std::size_t>(setup_.num_constraints), kNaN);
    r.pareto_value_si = kNaN;
  } else {
    r.objective_x0 = r.objective_trial = values->objective;
    r.max_violation_x0 = r.max_violation_trial = best.max_violation;
    r.constraint_violations = values->violations;
    r.pareto_value_si = values->traded_value_si;
  }
  point.usable = values != nullptr && run.state() != slp::RunState::kFailed &&
                 best.max_violation <= setup_.options.convergence_violation_tolerance;
  r.accepted = point.usable;
  if (!point.usable) {
    r.rejection_reason = run.state() == slp::RunState::kFailed || values == nullptr
                             ? absl::StrCat("the run failed: ", run.end_reason())
                             : absl::StrFormat("no feasible design: maxg %.4g at the best design", best.max_violation);
  }
}

slp::CycleRecord ParetoRun::RunCycle(const Point& point, int k, slp::CycleRecord record) const {
  record.pareto_point = k + 1;
  // The run's row h is the study's row point.rows[h]; the bound on a
  // second objective that is a sum has no row of the study's and is named
  // by its first term's.
  auto study_row = [&](int h) {
    if (h < 0 || static_cast<std::size_t>(h) >= point.rows.size()) return h;
    const int row = point.rows[static_cast<std::size_t>(h)];
    return row == kSumRow ? traded_rows_.front() : row;
  };
  record.worst_constraint_trial = study_row(record.worst_constraint_trial);
  record.worst_approximation_row = study_row(record.worst_approximation_row);
  return record;
}

ParetoRun::Analysed ParetoRun::Analyse(const AnalysisRecord& record) const {
  const slp::ProblemSpec& p = setup_.problem;
  Analysed a;
  a.x = Eigen::Map<const Eigen::VectorXd>(record.x_scaled.data(), static_cast<Eigen::Index>(record.x_scaled.size()));
  const Eigen::Map<const Eigen::VectorXd> terms(record.objective_terms.data(),
                                                static_cast<Eigen::Index>(record.objective_terms.size()));
  a.objective = slp::ObjectiveValue(p, terms);
  a.traded_value_si = TradedValue(record.constraint_values);
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

slp::AnalysisResult ParetoRun::ResultFor(const Point& point, const AnalysisRecord& record) const {
  slp::AnalysisResult result;
  result.request_id = record.request_id % kRequestStride;
  result.outcome = record.ok() ? slp::AnalysisOutcome::kOk : slp::AnalysisOutcome::kFailed;
  result.failure_reason = record.failure.reason;
  if (!record.ok()) return result;
  const Eigen::Map<const Eigen::VectorXd> terms(record.objective_terms.data(),
                                                static_cast<Eigen::Index>(record.objective_terms.size()));
  const Eigen::Map<const Eigen::VectorXd> values(record.constraint_values.data(),
                                                 static_cast<Eigen::Index>(record.constraint_values.size()));
  const bool traded_objective = &point == &points_[static_cast<std::size_t>(setup_.points - 1)];
  const double sum = setup_.traded_sum ? TradedValue(record.constraint_values) : kNaN;
  if (!traded_objective) {
    result.objective_terms = terms;
  } else if (setup_.traded_sum) {
    result.objective_terms = Eigen::VectorXd::Constant(1, sum / traded_scale_);
  } else {
    result.objective_terms.resize(static_cast<Eigen::Index>(traded_rows_.size()));
    for (std::size_t j = 0; j < traded_rows_.size(); ++j) {
      result.objective_terms[static_cast<Eigen::Index>(j)] =
          setup_.traded_factors[j] * values[traded_rows_[j]] / traded_scale_;
    }
  }
  result.constraint_values.resize(static_cast<Eigen::Index>(point.rows.size()));
  for (std::size_t j = 0; j < point.rows.size(); ++j) {
    const int h = point.rows[j];
    result.constraint_values[static_cast<Eigen::Index>(j)] = h == kSumRow ? sum : values[h];
  }
  if (!record.objective_gradients.empty()) {
    const std::size_t n = static_cast<std::size_t>(setup_.problem.num_variables());
    std::vector<double> objective_gradients;
    if (!traded_objective) {
      objective_gradients = record.objective_gradients;
    } else if (setup_.traded_sum) {
      objective_gradients = SumGradient(record.constraint_gradients, n);
      for (double& d : objective_gradients) d /= traded_scale_;
    } else {
      for (std::size_t j = 0; j < traded_rows_.size(); ++j) {
        const std::vector<double> row = PickRows(record.constraint_gradients, n, {traded_rows_[j]},
                                                 setup_.traded_factors[j] * (1.0 / traded_scale_));
        objective_gradients.insert(objective_gradients.end(), row.begin(), row.end());
      }
    }
    std::vector<double> constraint_gradients;
    constraint_gradients.reserve(point.rows.size() * n);
    for (int h : point.rows) {
      const std::vector<double> row =
          h == kSumRow ? SumGradient(record.constraint_gradients, n) : PickRows(record.constraint_gradients, n, {h}, 1.0);
      constraint_gradients.insert(constraint_gradients.end(), row.begin(), row.end());
    }
    AttachGradients(point.problem, objective_gradients, constraint_gradients, &result);
  }
  return result;
}

std::vector<slp::AnalysisRequest> ParetoRun::PendingRequests() const { return PendingRequestsOfPoints(points_); }

bool ParetoRun::IsPending(std::int64_t request_id) const { return IsPendingInPoints(points_, request_id); }

absl::Status ParetoRun::Submit(const AnalysisRecord& record) {
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

std::vector<slp::CycleRecord> ParetoRun::TakeNewRecords() { return std::exchange(new_records_, {}); }

}  // namespace mbopt::jobs
