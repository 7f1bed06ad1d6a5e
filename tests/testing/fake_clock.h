// A clock for analysis budgets (worker/budget/analysis_budget.h) that moves
// only when it is read: every reading is `step_s` later than the one before.
// A time limit then falls after a known number of budget checks, whatever
// the machine's speed. Copies share one time.
#pragma once

#include <cstdint>
#include <memory>

#include "worker/budget/analysis_budget.h"

namespace mbopt::testing {

class SteppingClock {
 public:
  explicit SteppingClock(double step_s) : state_(std::make_shared<State>()) { state_->step_s = step_s; }

  budget::AnalysisClock AsClock() const {
    return [state = state_] {
      ++state->reads;
      return state->now_s += state->step_s;
    };
  }
  std::int64_t reads() const { return state_->reads; }

 private:
  struct State {
    double now_s = 0.0;
    double step_s = 0.0;
    std::int64_t reads = 0;
  };
  std::shared_ptr<State> state_;
};

// A cancel flag that goes up at its `after`-th question and stays up.
class CancelAfter {
 public:
  explicit CancelAfter(std::int64_t after) : state_(std::make_shared<State>()) { state_->after = after; }

  budget::CancelRequested AsFlag() const {
    return [state = state_] { return ++state->asked >= state->after; };
  }
  std::int64_t asked() const { return state_->asked; }

 private:
  struct State {
    std::int64_t after = 0;
    std::int64_t asked = 0;
  };
  std::shared_ptr<State> state_;
};

}  // namespace mbopt::testing
