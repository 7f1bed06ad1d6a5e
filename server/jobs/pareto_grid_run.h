// The run of a Pareto front of three objectives (docs/study.md, "Three
// objectives"): the study's objective F1 and the largest values F2 and F3
// of two of its constraints, by the epsilon-constraint method over a grid
// of levels. One SLP run of the existing core per point, all in one job,
// keeping the contract ParetoRun keeps (front_run.h):
//  - points 0, 1, 2 are the anchors, each objective's own optimum with
//    both traded constraints left out (point 0 minimizes F1; points 1 and 2
//    minimize F2 and F3, each as a min-max over its rows divided by their
//    scale), all three started at once from the study's initial design;
//  - grid point (i, j), number 3 + i * levels + j, minimizes F1 with F2
//    bounded at its level i and F3 at its level j (spec::ParetoGridLevel),
//    between the least value of each (its anchor's) and the largest any
//    anchor has;
//  - a grid point starts once the anchors and its parent
//    (spec::ParetoGridWarmStartParents) have ended, from the parent's
//    result: a function of the study alone, so runs side by side on any
//    number of workers, answered in any order, give the same front bit for
//    bit;
//  - request ids, records in the points' order and each run's cycle
//    records just before its point's, as ParetoRun's (point_front_run.h).
//
// Pure: no I/O, no clock, no threads.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/statusor.h"
#include "server/jobs/point_front_run.h"

namespace mbopt::jobs {

struct ParetoGridSetup : FrontSetup {
  // The study constraints whose largest values are F2 and F3.
  std::array<int, 2> traded_constraints = {-1, -1};
  int levels = 0;  // per bounded objective, >= 2
};

// What ParetoGridRun keeps of an analysed design and of each point.
struct ParetoGridAnalysed : AnalysedDesign {
  std::array<double, 2> traded_si = {0, 0};  // F2, F3
};
struct ParetoGridRunPoint : FrontRunPoint<ParetoGridAnalysed> {
  std::array<double, 2> level_si;  // NaN for the anchors
  int objective = -1;              // the study's F, or 0 / 1: the run minimizes F2 / F3
};

class ParetoGridRun final : public PointFrontRun<ParetoGridSetup, ParetoGridRunPoint> {
 public:
  // InvalidArgument when the setup does not fit (a traded constraint with
  // no rows or rows of different limits, the same constraint twice, too
  // few levels).
  static absl::StatusOr<std::unique_ptr<ParetoGridRun>> Create(ParetoGridSetup setup, LpSolverFactory make_lp_solver);

 private:
  using Point = ParetoGridRunPoint;
  static constexpr int kStudyObjective = -1;

  ParetoGridRun(ParetoGridSetup setup, LpSolverFactory make_lp_solver);
  void StartRuns() override;
  void Start(int k, const Eigen::VectorXd& initial);
  void AnalyseTraded(const AnalysisRecord& record, Analysed* a) const override;
  void TranslateResult(const Point& point, const AnalysisRecord& record, slp::AnalysisResult* result) const override;
  void SetFrontFields(const Point& point, const Analysed* values, slp::CycleRecord* r) const override;
  // Which of F2, F3 row h belongs to; -1: neither.
  int TradedGroup(int row) const;

  std::array<std::vector<int>, 2> traded_rows_;
  std::array<double, 2> traded_scale_ = {1, 1};
};

}  // namespace mbopt::jobs
