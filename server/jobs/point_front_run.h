// The part of a front's run (FrontRun) that does not depend on how many
// objectives the front trades: its points' SLP runs, the analyses they are
// given, the records they end with and the emission of those records in
// the points' order. ParetoRun (two objectives) and ParetoGridRun (three)
// derive from it and keep only what differs: which points start when, the
// problems their runs solve, and the front's values in a point's record.
//
// Setup derives from FrontSetup, Point from FrontRunPoint.
//
// Pure: no I/O, no clock, no threads.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/status.h"
#include "server/jobs/analysis_record.h"
#include "server/jobs/front_run.h"
#include "server/jobs/point_runs.h"
#include "server/lp/linear_program.h"
#include "server/slp/options.h"
#include "server/slp/problem.h"
#include "server/slp/slp_optimizer.h"

namespace mbopt::jobs {

using LpSolverFactory = std::function<std::unique_ptr<lp::LpSolver>()>;

// What every front's setup has: the study it trades objectives of.
struct FrontSetup {
  slp::ProblemSpec problem;  // the study's problem: every objective term and row
  slp::SlpOptions options;   // the study's optimizer settings, for every run
  // The study constraint of each row (spec::ConstraintRow::constraint), and
  // how many the study has.
  std::vector<int> row_constraints;
  int num_constraints = 0;
};

// A design a point's run analysed, with what the point's record needs of
// it; a front adds the values of the objectives it trades.
struct AnalysedDesign {
  Eigen::VectorXd x;
  double objective = 0;            // the study's F
  std::vector<double> violations;  // per study constraint, against the study's limits
};

template <typename AnalysedT>
struct FrontRunPoint {
  using Analysed = AnalysedT;
  int parent = -1;                       // the point whose result starts this one
  slp::ProblemSpec problem;              // set when the run starts
  std::vector<int> rows;                 // the run's row h -> the study's row (a front may add rows of its own)
  std::unique_ptr<slp::SlpOptimizer> run;  // null until it starts
  std::vector<Analysed> analysed;        // its successful analyses, in arrival order
  bool ended = false;
  bool usable = false;                   // ended with a feasible result
  slp::CycleRecord record;               // set when it ends
  std::vector<slp::CycleRecord> cycles;  // its run's records, until they are emitted
};

// The helpers below are the templates' non-template parts (point_front_run.cc).

// Row `row` of a row-major matrix of `columns` columns, times `factor`,
// appended to `out`.
void AppendRow(const std::vector<double>& matrix, std::size_t columns, int row, double factor, std::vector<double>* out);

// A limit's scale as the study's layout scales one (spec/layout.cc), so a
// single run with this limit written in the study is the same problem.
double LimitScale(double limit);

// InvalidArgument unless the traded constraint's rows `rows` of `problem`
// share one limit and one scale: a front moves one limit.
absl::Status CheckTradedRowsShareLimit(const slp::ProblemSpec& problem, const std::vector<int>& rows);

// Makes `problem`'s constraint rows the study's rows `rows` (names, limits,
// scales), in that order; an entry below 0 is a row of the front's own,
// left unnamed at limit 0 and scale 1 for the caller to set.
void KeepStudyRows(const slp::ProblemSpec& study, const std::vector<int>& rows, slp::ProblemSpec* problem);

// Makes `problem` minimize `terms` of the traded rows (their values, each
// divided by the study's scale of its rows, so that F is of order one near
// the constraint's limit); the study's objective target does not apply.
void MinimizeTradedRows(int terms, slp::ProblemSpec* problem, slp::SlpOptions* options);

namespace front_detail {

absl::Status NotPending(std::int64_t request_id);
void CheckPointProblem(int k, const slp::ProblemSpec& problem);
void AnalyseDesign(const slp::ProblemSpec& study, const std::vector<int>& row_constraints, int num_constraints,
                   const AnalysisRecord& record, AnalysedDesign* a);
// The result's id and outcome; its values only when the analysis succeeded.
slp::AnalysisResult ResultHeader(const AnalysisRecord& record);
// A point that is never run: its record says why.
void FillNotRunRecord(int k, const Eigen::VectorXd& initial, const std::string& reason, int num_constraints,
                      slp::CycleRecord* r);
// Point k's run has ended with best design `best`, whose analysis is
// `values` (null: not among the run's successful analyses). Returns
// whether the point is usable: a feasible result.
bool FillEndedRecord(int k, const slp::SlpOptimizer& run, const slp::DesignPoint& best, const AnalysedDesign* values,
                     double violation_tolerance, int num_constraints, slp::CycleRecord* r);
bool SameBits(const Eigen::VectorXd& a, const Eigen::VectorXd& b);

}  // namespace front_detail

template <typename Setup, typename Point>
class PointFrontRun : public FrontRun {
 public:
  // Point k's request r has id k * kRequestStride + r: far more analyses than
  // a run may use (JobRunOptions::max_analyses).
  static constexpr std::int64_t kRequestStride = kPointRequestStride;

  std::vector<slp::AnalysisRequest> PendingRequests() const final { return PendingRequestsOfPoints(points_); }
  bool IsPending(std::int64_t request_id) const final { return IsPendingInPoints(points_, request_id); }
  absl::Status Submit(const AnalysisRecord& record) final;
  std::vector<slp::CycleRecord> TakeNewRecords() final { return std::exchange(new_records_, {}); }
  void LogRunCycles(bool log) final { log_run_cycles_ = log; }

  bool done() const final { return emitted_ == points_.size(); }
  int size() const final { return static_cast<int>(points_.size()); }
  int points_done() const final { return static_cast<int>(emitted_); }
  std::int64_t analyses_used() const final { return analyses_; }

 protected:
  using Analysed = typename Point::Analysed;

  PointFrontRun(Setup setup, LpSolverFactory make_lp_solver)
      : setup_(std::move(setup)), make_lp_solver_(std::move(make_lp_solver)) {}

  // Starts the runs whose inputs are known, and ends unrun the points that
  // cannot run; called once the front is made and after each point ends.
  virtual void StartRuns() = 0;
  // The values of the traded objectives at an analysed design.
  virtual void AnalyseTraded(const AnalysisRecord& record, Analysed* a) const = 0;
  // The objective terms, constraint values and gradients point's run sees
  // of a successful analysis (record, in the study's shape).
  virtual void TranslateResult(const Point& point, const AnalysisRecord& record, slp::AnalysisResult* result) const = 0;
  // The record's front fields: the point's levels, and the traded values
  // at its result (values null: none).
  virtual void SetFrontFields(const Point& point, const Analysed* values, slp::CycleRecord* r) const = 0;
  // The study's row for an entry of a point's rows.
  virtual int StudyRow(int entry) const { return entry; }

  // Starts point k's run on `problem` (which must be valid).
  void StartRun(int k, slp::ProblemSpec problem, const slp::SlpOptions& options) {
    Point& point = points_[static_cast<std::size_t>(k)];
    front_detail::CheckPointProblem(k, problem);
    point.problem = problem;
    point.run = std::make_unique<slp::SlpOptimizer>(std::move(problem), options, make_lp_solver_());
  }
  void EndWithoutRun(int k, const std::string& reason) {
    Point& point = points_[static_cast<std::size_t>(k)];
    point.ended = true;
    point.usable = false;
    front_detail::FillNotRunRecord(k, setup_.problem.initial, reason, setup_.num_constraints, &point.record);
    SetFrontFields(point, nullptr, &point.record);
  }

  Setup setup_;
  std::vector<Point> points_;

 private:
  void End(int k);
  // A run's record as the log keeps it: its point's number, the study's rows.
  slp::CycleRecord RunCycle(const Point& point, int k, slp::CycleRecord record) const;

  LpSolverFactory make_lp_solver_;
  std::int64_t analyses_ = 0;
  std::size_t emitted_ = 0;
  bool log_run_cycles_ = true;
  std::vector<slp::CycleRecord> new_records_;
};

template <typename Setup, typename Point>
absl::Status PointFrontRun<Setup, Point>::Submit(const AnalysisRecord& record) {
  if (!IsPending(record.request_id)) return front_detail::NotPending(record.request_id);
  const int k = static_cast<int>(record.request_id / kRequestStride);
  Point& point = points_[static_cast<std::size_t>(k)];
  ++analyses_;
  if (record.ok()) {
    Analysed a;
    front_detail::AnalyseDesign(setup_.problem, setup_.row_constraints, setup_.num_constraints, record, &a);
    AnalyseTraded(record, &a);
    point.analysed.push_back(std::move(a));
  }
  slp::AnalysisResult result = front_detail::ResultHeader(record);
  result.request_id = record.request_id % kRequestStride;
  if (record.ok()) TranslateResult(point, record, &result);
  const absl::Status submitted = point.run->SubmitResult(std::move(result));
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

template <typename Setup, typename Point>
void PointFrontRun<Setup, Point>::End(int k) {
  Point& point = points_[static_cast<std::size_t>(k)];
  const slp::SlpOptimizer& run = *point.run;
  point.ended = true;
  const slp::DesignPoint best = run.best_design();
  const Analysed* values = nullptr;
  for (auto it = point.analysed.rbegin(); it != point.analysed.rend() && values == nullptr; ++it) {
    if (front_detail::SameBits(it->x, best.x)) values = &*it;
  }
  point.usable = front_detail::FillEndedRecord(k, run, best, values, setup_.options.convergence_violation_tolerance,
                                               setup_.num_constraints, &point.record);
  SetFrontFields(point, values, &point.record);
}

template <typename Setup, typename Point>
slp::CycleRecord PointFrontRun<Setup, Point>::RunCycle(const Point& point, int k, slp::CycleRecord record) const {
  record.pareto_point = k + 1;
  auto study_row = [&](int h) {
    if (h < 0 || static_cast<std::size_t>(h) >= point.rows.size()) return h;
    return StudyRow(point.rows[static_cast<std::size_t>(h)]);
  };
  record.worst_constraint_trial = study_row(record.worst_constraint_trial);
  record.worst_approximation_row = study_row(record.worst_approximation_row);
  return record;
}

}  // namespace mbopt::jobs
