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
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/statusor.h"
#include "server/jobs/point_front_run.h"

namespace mbopt::jobs {

struct ParetoSetup : FrontSetup {
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

// What ParetoRun keeps of an analysed design and of each point.
struct ParetoAnalysed : AnalysedDesign {
  double traded_value_si = 0;  // the second objective (ParetoRun::TradedValue)
};
struct ParetoRunPoint : FrontRunPoint<ParetoAnalysed> {
  double level_si = 0;  // NaN for the anchors; an added point's parent is set when it starts
};

class ParetoRun final : public PointFrontRun<ParetoSetup, ParetoRunPoint> {
 public:
  // InvalidArgument when the setup does not fit (no rows for the traded
  // constraint, rows of different limits, too few points).
  static absl::StatusOr<std::unique_ptr<ParetoRun>> Create(ParetoSetup setup, LpSolverFactory make_lp_solver);

 private:
  using Point = ParetoRunPoint;

  ParetoRun(ParetoSetup setup, LpSolverFactory make_lp_solver);
  void StartRuns() override;
  // Generation `first` (points or points + refine) of `count` points,
  // chosen on the front of points 0 to first - 1 once they have ended.
  void StartRefinement(std::size_t first, int count);
  void Start(int k, const Eigen::VectorXd& initial);
  void AnalyseTraded(const AnalysisRecord& record, Analysed* a) const override;
  void TranslateResult(const Point& point, const AnalysisRecord& record, slp::AnalysisResult* result) const override;
  void SetFrontFields(const Point& point, const Analysed* values, slp::CycleRecord* r) const override;
  // The bound on a second objective that is a sum has no row of the
  // study's and is named by its first term's.
  int StudyRow(int entry) const override;
  bool IsTraded(int row) const;
  // The second objective at the study's row values, and its gradient
  // from the rows' (row-major, `columns` each; none when empty).
  double TradedValue(const std::vector<double>& row_values) const;
  std::vector<double> SumGradient(const std::vector<double>& row_gradients, std::size_t columns) const;

  // A point's row that is the traded rows' weighted sum (a second
  // objective that is a sum).
  static constexpr int kSumRow = -1;

  std::vector<int> traded_rows_;
  double traded_scale_ = 1;  // the traded rows' scale in the study
};

}  // namespace mbopt::jobs
