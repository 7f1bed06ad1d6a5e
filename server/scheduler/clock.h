// The scheduler's notion of time, injected so that lease expiry can be tested
// without waiting: production uses a monotonic clock, tests a fake one that
// moves only when the test says.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>

namespace mbopt::scheduler {

class Clock {
 public:
  virtual ~Clock() = default;
  // Milliseconds on a monotonic scale (not wall time).
  virtual std::int64_t NowMs() const = 0;
};

class SteadyClock : public Clock {
 public:
  std::int64_t NowMs() const override {
    return std::chrono::duration_cast<std::chrono::milliseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
};

// A clock for tests: starts at `start_ms` and moves only by Advance().
class FakeClock : public Clock {
 public:
  explicit FakeClock(std::int64_t start_ms = 1'000'000) : now_ms_(start_ms) {}
  std::int64_t NowMs() const override { return now_ms_.load(); }
  void Advance(std::int64_t ms) { now_ms_ += ms; }

 private:
  std::atomic<std::int64_t> now_ms_;
};

}  // namespace mbopt::scheduler
