// Calls per second per user: a token bucket per name, refilled at `rate`
// per second and holding at most `burst` calls, so a script that polls in a
// tight loop is slowed down without touching anyone else's calls. Time is
// the caller's (milliseconds of a monotonic clock) so that tests need not
// sleep.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <string>

namespace mbopt::service {

class CallRateLimiter {
 public:
  // `calls_per_second` > 0; the bucket holds twice that many calls (at
  // least one).
  explicit CallRateLimiter(double calls_per_second);

  // Whether `name` may make one more call at `now_ms`; takes it if so.
  bool Allow(const std::string& name, std::int64_t now_ms);

  double calls_per_second() const { return rate_per_ms_ * 1000.0; }

 private:
  struct Bucket {
    double calls = 0;
    std::int64_t last_ms = 0;
  };
  const double rate_per_ms_;
  const double burst_;
  std::mutex mutex_;
  std::map<std::string, Bucket> buckets_;
};

}  // namespace mbopt::service
