#include "worker/service/backoff.h"

#include <algorithm>
#include <cmath>

namespace mbopt::worker {

Backoff::Backoff(const BackoffOptions& options, std::uint64_t seed)
    : options_(options), rng_(seed) {}

std::chrono::milliseconds Backoff::Next() {
  const double initial_ms = static_cast<double>(options_.initial.count());
  const double max_ms = static_cast<double>(options_.max.count());
  // Exponent capped so that the power cannot overflow for long outages.
  const double exponent = std::min(attempts_, 60);
  const double base_ms = std::min(max_ms, initial_ms * std::pow(options_.multiplier, exponent));
  ++attempts_;
  std::uniform_real_distribution<double> spread(1.0 - options_.jitter, 1.0);
  return std::chrono::milliseconds(static_cast<long>(std::llround(base_ms * spread(rng_))));
}

}  // namespace mbopt::worker
