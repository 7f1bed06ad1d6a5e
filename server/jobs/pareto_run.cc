#include "server/jobs/pareto_run.h"

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
  if (absl::Status shared = CheckTradedRowsShareLimit(setup.problem, traded); !shared.ok()) return shared;
  std::unique_ptr<ParetoRun> run(new ParetoRun(std::move(setup), std::move(make_lp_solver)));
  run->traded_rows_ = std::move(traded);
  run->traded_scale_ = run->setup_.problem.constraint_scales[run->traded_rows_[0]];
  run->StartRuns();
  return run;
}

ParetoRun::ParetoRun(ParetoSetup setup, LpSolverFactory make_lp_solver)
    : PointFrontRun(std::move(setup), std::move(make_lp_solver)) {
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
  const bool bounds_sum = !anchor && setup_.traded_sum;
  if (bounds_sum) point.rows.push_back(kSumRow);
  if (leaves_out_traded) {
    KeepStudyRows(study, point.rows, &problem);
    if (bounds_sum) {
      const auto row = static_cast<Eigen::Index>(point.rows.size() - 1);
      problem.constraint_names.back() = "second objective";
      problem.constraint_limits[row] = point.level_si;
      problem.constraint_scales[row] = LimitScale(point.level_si);
    }
  } else {
    // An ordinary limit at the level, scaled as the study scales a limit.
    for (std::size_t j = 0; j < traded_rows_.size(); ++j) {
      const double limit = point.level_si / setup_.traded_factors[j];
      problem.constraint_limits[traded_rows_[j]] = limit;
      problem.constraint_scales[traded_rows_[j]] = LimitScale(limit);
    }
  }
  if (k == setup_.points - 1) {
    MinimizeTradedRows(setup_.traded_sum ? 1 : static_cast<int>(traded_rows_.size()), &problem, &options);
  }
  StartRun(k, std::move(problem), options);
}

void ParetoRun::SetFrontFields(const Point& point, const Analysed* values, slp::CycleRecord* r) const {
  r->pareto_level_si = point.level_si;
  r->pareto_value_si = values == nullptr ? kNaN : values->traded_value_si;
}

int ParetoRun::StudyRow(int entry) const { return entry == kSumRow ? traded_rows_.front() : entry; }

void ParetoRun::AnalyseTraded(const AnalysisRecord& record, Analysed* a) const {
  a->traded_value_si = TradedValue(record.constraint_values);
}

void ParetoRun::TranslateResult(const Point& point, const AnalysisRecord& record, slp::AnalysisResult* out) const {
  slp::AnalysisResult& result = *out;
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
        AppendRow(record.constraint_gradients, n, traded_rows_[j], setup_.traded_factors[j] * (1.0 / traded_scale_),
                  &objective_gradients);
      }
    }
    std::vector<double> constraint_gradients;
    constraint_gradients.reserve(point.rows.size() * n);
    for (int h : point.rows) {
      if (h != kSumRow) {
        AppendRow(record.constraint_gradients, n, h, 1.0, &constraint_gradients);
        continue;
      }
      const std::vector<double> sum_gradient = SumGradient(record.constraint_gradients, n);
      constraint_gradients.insert(constraint_gradients.end(), sum_gradient.begin(), sum_gradient.end());
    }
    AttachGradients(point.problem, objective_gradients, constraint_gradients, &result);
  }
}

}  // namespace mbopt::jobs
