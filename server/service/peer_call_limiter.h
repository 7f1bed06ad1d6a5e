// Calls held open per peer address: watches, workers' attach streams, long
// polls for tasks and results sent in pieces each hold one of the server's
// call threads (server.h, max_call_threads) for as long as they last. One
// address that opens many of them would take every thread and lock out
// everyone else; this caps what each address may hold, so the thread quota
// is shared. Short calls are not counted: they give their thread back at
// once.
#pragma once

#include <map>
#include <mutex>
#include <string>
#include <string_view>

#include "absl/status/statusor.h"

namespace mbopt::service {

class PeerCallLimiter {
 public:
  // `max_per_peer` <= 0: no limit.
  explicit PeerCallLimiter(int max_per_peer) : max_per_peer_(max_per_peer) {}

  // One held call; gives its place back when destroyed.
  class Slot {
   public:
    Slot() = default;
    Slot(Slot&& other) noexcept : limiter_(other.limiter_), address_(std::move(other.address_)) {
      other.limiter_ = nullptr;
    }
    Slot& operator=(Slot&& other) noexcept;
    Slot(const Slot&) = delete;
    Slot& operator=(const Slot&) = delete;
    ~Slot() { Release(); }

   private:
    friend class PeerCallLimiter;
    Slot(PeerCallLimiter* limiter, std::string address) : limiter_(limiter), address_(std::move(address)) {}
    void Release();
    PeerCallLimiter* limiter_ = nullptr;
    std::string address_;
  };

  // A place for one more held call of `peer` (gRPC's peer string), or
  // ResourceExhausted naming the address, its count and the option.
  absl::StatusOr<Slot> Take(std::string_view peer);

  // How many calls `peer`'s address holds now.
  int Held(std::string_view peer) const;

  // The address of a gRPC peer string without its port: every connection
  // of a machine counts together ("ipv4:10.0.0.5:41234" -> "ipv4:10.0.0.5",
  // "ipv6:[::1]:5000" -> "ipv6:[::1]"; anything else, e.g. a Unix socket, as
  // it is).
  static std::string Address(std::string_view peer);

 private:
  const int max_per_peer_;
  mutable std::mutex mutex_;
  std::map<std::string, int, std::less<>> held_;
};

}  // namespace mbopt::service
