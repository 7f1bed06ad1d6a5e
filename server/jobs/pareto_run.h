// The run of a Pareto front (spec/pareto.h): one SLP run of the existing
// core per point, all in one job. It plays the part the SLP core plays in an
// optimization job and keeps its contract, as DesignSetRun does, so the job
// manager, the store, the scheduler and resume need nothing new:
//  - every point's run is a slp::SlpOptimizer of its own (own LP solver),
//    whose problem is the study's with the second objective's rows (the
//    traded rows: a constraint's, or an objective's) left out (point 0),
//    made the objective (the last point: a min-max over the rows, each
//    times its factor and divided by the rows' scale, or their weighted
//    sum), or bounded at the point's level (the points between: each row
//    at level / factor, or one row, the weighted sum, at the level);
//  - request ids: point k's request r is k * kRequestStride + r, so the
//    runs' requests never collide and a result finds its run by its id;
//  - a run starts when what it needs is known: the anchors at once, the
//    others when both anchors and the point that warm-starts them
//    (spec::ParetoWarmStartParents) have ended. Each run's state is a
//    function of its own results only, so runs side by side on any number
//    of workers, answered in any order, give the same front bit for bit;
//  - refinement (setup.refine > 0): once the first `points` have ended, the
//    segments of their front to halve are chosen (spec::RefinementSegments)
//    and the added points start side by side, each with its level halfway
//    between its segment's ends' values, warm-started from the end with the
//    larger value (nearer point 1, as the points between). Added points
//    the front has no segment for end unrun, saying why, so a front always
//    has points + refine records; refine_again > 0: once those have ended,
//    a second generation the same way, its segments chosen on the front of
//    all points + refine points;
//  - one record per point (a design set's record with the Pareto fields,
//    slp::CycleRecord), emitted in the points' order: point k's once points
//    0..k have ended, so the record log does not depend on the order of
//    results either, and a replay of the logged analyses emits it again;
//  - each point's run's own cycle records (its history, pareto_point set),
//    held until the point's record goes out and emitted just before it:
//    runs side by side emit their cycles interleaved in the order of their
//    results, which the log must not depend on. A job logged before the
//    histories were (LogRunCycles(false)) resumes without them.
//
// Pure: no I/O, no clock, no threads.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "server/jobs/analysis_record.h"
#include "server/jobs/front_run.h"
#include "server/jobs/point_runs.h"
#include "server/lp/linear_program.h"
#include "server/slp/options.h"
#include "server/slp/problem.h"
#include "server/slp/slp_optimizer.h"

namespace mbopt::jobs {

using LpSolverFactory = std::function<std::unique_ptr<lp::LpSolver>()>;

struct ParetoSetup {
  slp::ProblemSpec problem;  // the study's problem: every objective term and row
  slp::SlpOptions options;   // the study's optimizer settings, for every run
  // The study constraint of each row (spec::ConstraintRow::constraint), and
  // how many the study has.
  std::vector<int> row_constraints;
  int num_constraints = 0;
  // The rows of the second objective: those whose row_constraints entry is
  // traded_constraint (a study constraint, or spec::kSecondObjectiveRow).
  int traded_constraint = -1;
  // One per traded row, in row order; empty: all 1. The second objective
  // is F2 = max_h factor_h * g_h (each factor > 0), or with traded_sum
  // F2 = sum_h factor_h * g_h (spec::StudyLayout::second_objective_factors).
  std::vector<double> traded_factors;
  bool traded_sum = false;
  int points = 0;              // >= 3
  int refine = 0;              // added points, 0 to points - 1
  int refine_again = 0;        // a second generation, 0 to points + refine - 1; only with refine > 0
};

class ParetoRun final : public FrontRun {
 public:
  // Point k's request r has id k * kRequestStride + r: far more analyses than
  // a run may use (JobRunOptions::max_analyses).
  static constexpr std::int64_t kRequestStride = kPointRequestStride;

  // InvalidArgument when the setup does not fit (no rows for the traded
  // constraint, rows of different limits, too few points).
  static absl::StatusOr<std::unique_ptr<ParetoRun>> Create(ParetoSetup setup, LpSolverFactory make_lp_solver);

  std::vector<slp::AnalysisRequest> PendingRequests() const override;
  bool IsPending(std::int64_t request_id) const override;
  absl::Status Submit(const AnalysisRecord& record) override;
  std::vector<slp::CycleRecord> TakeNewRecords() override;
  void LogRunCycles(bool log) override { log_run_cycles_ = log; }

  bool done() const override { return emitted_ == points_.size(); }
  int size() const override { return static_cast<int>(points_.size()); }
  int points_done() const override { return static_cast<int>(emitted_); }
  std::int64_t analyses_used() const override { return analyses_; }

 private:
  // A design a run analysed, with what the point's record needs of it.
  struct Analysed {
    Eigen::VectorXd x;
    double objective = 0;                 // the study's F
    double traded_value_si = 0;           // the second objective (TradedValue)
    std::vector<double> violations;       // per study constraint, against the study's limits
  };
  struct Point {
    int parent = -1;                      // for an added point: set when it starts
    double level_si = 0;                  // NaN for the anchors
    slp::ProblemSpec problem;             // set when the run starts
    // The run's row h -> the study's row, or kSumRow: the traded rows'
    // weighted sum (a second objective that is a sum).
    std::vector<int> rows;
    std::unique_ptr<slp::SlpOptimizer> run;  // null until it starts
    std::vector<Analysed> analysed;       // its successful analyses, in arrival order
    bool ended = false;
    bool usable = false;                  // ended with a feasible result
    std::string not_run_reason;           // "" unless the point was never run
    slp::CycleRecord record;              // set when it ends
    std::vector<slp::CycleRecord> cycles;  // its run's records, until they are emitted
  };

  explicit ParetoRun(ParetoSetup setup, LpSolverFactory make_lp_solver);
  void StartRuns();
  // Generation `first` (points or points + refine) of `count` points,
  // chosen on the front of points 0 to first - 1 once they have ended.
  void StartRefinement(std::size_t first, int count);
  void Start(int k, const Eigen::VectorXd& initial);
  void EndWithoutRun(int k, const std::string& reason);
  void End(int k);
  // A run's record as the log keeps it: its point's number, the study's rows.
  slp::CycleRecord RunCycle(const Point& point, int k, slp::CycleRecord record) const;
  slp::AnalysisResult ResultFor(const Point& point, const AnalysisRecord& record) const;
  Analysed Analyse(const AnalysisRecord& record) const;
  bool IsTraded(int row) const;
  // The second objective at the study's row values, and its gradient
  // from the rows' (row-major, `columns` each; none when empty).
  double TradedValue(const std::vector<double>& row_values) const;
  std::vector<double> SumGradient(const std::vector<double>& row_gradients, std::size_t columns) const;

  static constexpr int kSumRow = -1;

  ParetoSetup setup_;
  LpSolverFactory make_lp_solver_;
  std::vector<int> traded_rows_;
  double traded_scale_ = 1;  // the traded rows' scale in the study
  std::vector<Point> points_;
  std::int64_t analyses_ = 0;
  std::size_t emitted_ = 0;
  bool log_run_cycles_ = true;
  std::vector<slp::CycleRecord> new_records_;
};

}  // namespace mbopt::jobs
