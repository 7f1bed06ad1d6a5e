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
//    records just before its point's, as ParetoRun's.
//
// Pure: no I/O, no clock, no threads.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
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

struct ParetoGridSetup {
  slp::ProblemSpec problem;  // the study's problem: every objective term and row
  slp::SlpOptions options;   // the study's optimizer settings, for every run
  // The study constraint of each row (spec::ConstraintRow::constraint), and
  // how many the study has.
  std::vector<int> row_constraints;
  int num_constraints = 0;
  // The study constraints whose largest values are F2 and F3.
  std::array<int, 2> traded_constraints = {-1, -1};
  int levels = 0;  // per bounded objective, >= 2
};

class ParetoGridRun final : public FrontRun {
 public:
  // Point k's request r has id k * kRequestStride + r, as ParetoRun's.
  static constexpr std::int64_t kRequestStride = kPointRequestStride;

  // InvalidArgument when the setup does not fit (a traded constraint with
  // no rows or rows of different limits, the same constraint twice, too
  // few levels).
  static absl::StatusOr<std::unique_ptr<ParetoGridRun>> Create(ParetoGridSetup setup,
                                                               std::function<std::unique_ptr<lp::LpSolver>()> make_lp_solver);

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
  static constexpr int kStudyObjective = -1;

  struct Analysed {
    Eigen::VectorXd x;
    double objective = 0;                  // the study's F
    std::array<double, 2> traded_si = {0, 0};  // F2, F3
    std::vector<double> violations;        // per study constraint, against the study's limits
  };
  struct Point {
    int parent = -1;
    std::array<double, 2> level_si;        // NaN for the anchors
    int objective = kStudyObjective;       // or 0 / 1: the run minimizes F2 / F3
    slp::ProblemSpec problem;              // set when the run starts
    std::vector<int> rows;                 // the run's row h -> the study's row
    std::unique_ptr<slp::SlpOptimizer> run;
    std::vector<Analysed> analysed;
    bool ended = false;
    bool usable = false;
    slp::CycleRecord record;
    std::vector<slp::CycleRecord> cycles;
  };

  ParetoGridRun(ParetoGridSetup setup, std::function<std::unique_ptr<lp::LpSolver>()> make_lp_solver);
  void StartRuns();
  void Start(int k, const Eigen::VectorXd& initial);
  void EndWithoutRun(int k, const std::string& reason);
  void End(int k);
  slp::CycleRecord RunCycle(const Point& point, int k, slp::CycleRecord record) const;
  slp::AnalysisResult ResultFor(const Point& point, const AnalysisRecord& record) const;
  Analysed Analyse(const AnalysisRecord& record) const;
  // Which of F2, F3 row h belongs to; -1: neither.
  int TradedGroup(int row) const;

  ParetoGridSetup setup_;
  std::function<std::unique_ptr<lp::LpSolver>()> make_lp_solver_;
  std::array<std::vector<int>, 2> traded_rows_;
  std::array<double, 2> traded_scale_ = {1, 1};
  std::vector<Point> points_;
  std::int64_t analyses_ = 0;
  std::size_t emitted_ = 0;
  bool log_run_cycles_ = true;
  std::vector<slp::CycleRecord> new_records_;
};

}  // namespace mbopt::jobs
