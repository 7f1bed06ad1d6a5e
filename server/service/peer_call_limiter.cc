#include "server/service/peer_call_limiter.h"

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace mbopt::service {

PeerCallLimiter::Slot& PeerCallLimiter::Slot::operator=(Slot&& other) noexcept {
  if (this != &other) {
    Release();
    limiter_ = other.limiter_;
    address_ = std::move(other.address_);
    other.limiter_ = nullptr;
  }
  return *this;
}

void PeerCallLimiter::Slot::Release() {
  if (limiter_ == nullptr) return;
  std::lock_guard<std::mutex> lock(limiter_->mutex_);
  auto it = limiter_->held_.find(address_);
  if (it != limiter_->held_.end() && --it->second <= 0) limiter_->held_.erase(it);
  limiter_ = nullptr;
}

std::string PeerCallLimiter::Address(std::string_view peer) {
  const bool ipv4 = peer.rfind("ipv4:", 0) == 0;
  const bool ipv6 = peer.rfind("ipv6:", 0) == 0;
  if (!ipv4 && !ipv6) return std::string(peer);
  const size_t colon = peer.rfind(':');
  // "ipv6:[::1]:5000": the port follows the closing bracket.
  if (ipv6 && (colon == std::string_view::npos || colon == 0 || peer[colon - 1] != ']')) return std::string(peer);
  if (colon <= 4) return std::string(peer);
  return std::string(peer.substr(0, colon));
}

absl::StatusOr<PeerCallLimiter::Slot> PeerCallLimiter::Take(std::string_view peer) {
  std::string address = Address(peer);
  std::lock_guard<std::mutex> lock(mutex_);
  int& held = held_[address];
  if (max_per_peer_ > 0 && held >= max_per_peer_) {
    if (held == 0) held_.erase(address);
    return absl::ResourceExhaustedError(
        absl::StrCat(address, " holds ", held, " calls open (watches, attach streams, long polls), the server's "
                     "limit per address (mbopt-server --max-held-calls-per-peer ", max_per_peer_, ")"));
  }
  ++held;
  return Slot(this, std::move(address));
}

int PeerCallLimiter::Held(std::string_view peer) const {
  std::lock_guard<std::mutex> lock(mutex_);
  auto it = held_.find(Address(peer));
  return it == held_.end() ? 0 : it->second;
}

}  // namespace mbopt::service
