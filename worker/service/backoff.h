// Reconnection delays of a worker whose server went away: exponential,
// capped, with jitter so that a fleet of workers does not reconnect in
// lockstep after a server restart. The jitter only spreads reconnections in
// time; it has no influence on any result.
#pragma once

#include <chrono>
#include <cstdint>
#include <random>

namespace mbopt::worker {

struct BackoffOptions {
  std::chrono::milliseconds initial{100};
  std::chrono::milliseconds max{5000};
  double multiplier = 2.0;
  // Each delay is drawn uniformly from [(1 - jitter) d, d].
  double jitter = 0.5;
};

class Backoff {
 public:
  Backoff(const BackoffOptions& options, std::uint64_t seed);
  // The next delay: initial, then multiplied after each call, up to max.
  std::chrono::milliseconds Next();
  // After a success: the next delay is `initial` again.
  void Reset() { attempts_ = 0; }
  int attempts() const { return attempts_; }

 private:
  BackoffOptions options_;
  std::mt19937_64 rng_;
  int attempts_ = 0;
};

}  // namespace mbopt::worker
