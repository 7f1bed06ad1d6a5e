// The budget of one analysis: a deadline, a step budget and a cancel flag,
// checked by every loop of the engine that can run long (integrations,
// kinematic and static sweeps, continuation, Newton).
//
// The engine reads no clock: whoever runs an analysis hands it a clock (the
// worker and `mbopt-worker eval` a monotonic one, tests a fake one) and,
// optionally, a question "has this analysis been cancelled?" (the worker
// asks whether the task's job was cancelled). Without a clock there is no
// deadline and the report's wall time is 0; that keeps an analysis a pure
// function of its inputs, and makes a time limit testable without waiting.
//
// One budget serves one analysis on one thread: it counts the steps charged
// to it and is not copied between analyses (ForAnalysis makes a new one).
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <string>

#include "spec/analysis_outcome.h"

namespace mbopt::budget {

// Seconds on a monotonic clock, from any fixed origin.
using AnalysisClock = std::function<double()>;
// True once the analysis should stop.
using CancelRequested = std::function<bool()>;

class AnalysisBudget {
 public:
  // No deadline, no step limit, never cancelled.
  AnalysisBudget() = default;
  // The caller's clock and cancel flag (either may be empty), with no
  // deadline and no step limit yet.
  AnalysisBudget(AnalysisClock clock, CancelRequested cancel_requested);

  // The budget of one analysis under this one: the same clock and cancel
  // flag, the deadline moved to `max_wall_seconds` from now when that is
  // earlier (<= 0 or no clock: unchanged), and a fresh count of at most
  // `max_steps` steps (<= 0: no limit).
  AnalysisBudget ForAnalysis(double max_wall_seconds, std::int64_t max_steps) const;

  // The clock's reading, 0 without a clock: the caller's measure of an
  // analysis' wall time.
  double NowSeconds() const { return clock_ ? clock_() : 0.0; }

  // Ok, or why the analysis must stop at simulated time `t_s`: kCancelled
  // when the cancel flag is up, kTimeLimit past the deadline. Cheap enough
  // to call once per right-hand side.
  spec::AnalysisFailure Check(double t_s) const;
  // The same without building a reason, for C callbacks that only return a
  // code: true when Check would fail.
  bool Exhausted() const;

  // Charges `steps` steps (continuation steps, position solves) at
  // simulated time `t_s`: ok, or a kTimeLimit failure naming the step
  // budget once it is spent, or Check's failure.
  spec::AnalysisFailure ChargeSteps(std::int64_t steps, double t_s);

  std::int64_t steps_used() const { return steps_used_; }
  std::int64_t max_steps() const { return max_steps_; }
  bool has_deadline() const { return deadline_s_ < std::numeric_limits<double>::infinity(); }

 private:
  AnalysisClock clock_;
  CancelRequested cancel_requested_;
  double deadline_s_ = std::numeric_limits<double>::infinity();  // on clock_'s scale
  double max_wall_seconds_ = 0.0;  // the limit that set the deadline, for the reason
  std::int64_t max_steps_ = 0;     // <= 0: none
  std::int64_t steps_used_ = 0;
};

}  // namespace mbopt::budget
