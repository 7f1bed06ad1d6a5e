#include "server/service/call_rate_limiter.h"

#include <algorithm>

namespace mbopt::service {

CallRateLimiter::CallRateLimiter(double calls_per_second)
    : rate_per_ms_(calls_per_second / 1000.0), burst_(std::max(1.0, 2.0 * calls_per_second)) {}

bool CallRateLimiter::Allow(const std::string& name, std::int64_t now_ms) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto [it, inserted] = buckets_.try_emplace(name, Bucket{burst_, now_ms});
  Bucket& bucket = it->second;
  if (!inserted) {
    const std::int64_t elapsed_ms = std::max<std::int64_t>(0, now_ms - bucket.last_ms);
    bucket.calls = std::min(burst_, bucket.calls + static_cast<double>(elapsed_ms) * rate_per_ms_);
    bucket.last_ms = now_ms;
  }
  if (bucket.calls < 1.0) return false;
  bucket.calls -= 1.0;
  return true;
}

}  // namespace mbopt::service
