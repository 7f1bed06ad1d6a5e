// The process' monotonic clock in seconds, from an arbitrary origin: what
// the programs (the worker, `mbopt-worker eval`, in-process runs) hand the
// analysis engine as its clock. The engine itself reads no clock
// (worker/budget/analysis_budget.h), so that its tests can run on a fake one.
#pragma once

#include <chrono>

namespace mbopt {

inline double MonotonicSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace mbopt
