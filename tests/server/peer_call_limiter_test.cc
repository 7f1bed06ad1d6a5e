// The count of calls held open per peer address (peer_call_limiter.h).
#include "server/service/peer_call_limiter.h"

#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace mbopt::service {
namespace {

using ::testing::HasSubstr;

TEST(PeerCallLimiter, ConnectionsOfOneAddressCountTogetherUpToTheLimit) {
  PeerCallLimiter limiter(2);
  std::vector<PeerCallLimiter::Slot> held;
  for (const char* peer : {"ipv4:10.0.0.5:41234", "ipv4:10.0.0.5:41235"}) {
    absl::StatusOr<PeerCallLimiter::Slot> slot = limiter.Take(peer);
    ASSERT_TRUE(slot.ok()) << slot.status();
    held.push_back(*std::move(slot));
  }
  const absl::StatusOr<PeerCallLimiter::Slot> third = limiter.Take("ipv4:10.0.0.5:50000");
  ASSERT_EQ(third.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(third.status().message(), HasSubstr("ipv4:10.0.0.5 holds 2 calls open"));
  EXPECT_THAT(third.status().message(), HasSubstr("--max-held-calls-per-peer 2"));
  // Another address is not affected.
  EXPECT_TRUE(limiter.Take("ipv4:10.0.0.6:41234").ok());
  // A call that ends gives its place back.
  held.pop_back();
  EXPECT_EQ(limiter.Held("ipv4:10.0.0.5:1"), 1);
  EXPECT_TRUE(limiter.Take("ipv4:10.0.0.5:50001").ok());
  held.clear();
  EXPECT_EQ(limiter.Held("ipv4:10.0.0.5:1"), 0);
}

TEST(PeerCallLimiter, AddressesDropTheirPortOnly) {
  EXPECT_EQ(PeerCallLimiter::Address("ipv4:127.0.0.1:5000"), "ipv4:127.0.0.1");
  EXPECT_EQ(PeerCallLimiter::Address("ipv6:[::1]:5000"), "ipv6:[::1]");
  EXPECT_EQ(PeerCallLimiter::Address("ipv6:%5B::1%5D:5000"), "ipv6:%5B::1%5D:5000");
  EXPECT_EQ(PeerCallLimiter::Address("unix:/run/mbopt.sock"), "unix:/run/mbopt.sock");
  EXPECT_EQ(PeerCallLimiter::Address(""), "");
}

TEST(PeerCallLimiter, NoLimitTakesEverything) {
  PeerCallLimiter limiter(0);
  std::vector<PeerCallLimiter::Slot> held;
  for (int i = 0; i < 1000; ++i) {
    absl::StatusOr<PeerCallLimiter::Slot> slot = limiter.Take("ipv4:10.0.0.5:1");
    ASSERT_TRUE(slot.ok());
    held.push_back(*std::move(slot));
  }
  EXPECT_EQ(limiter.Held("ipv4:10.0.0.5:2"), 1000);
}

}  // namespace
}  // namespace mbopt::service
