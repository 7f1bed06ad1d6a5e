#include "common/packed_doubles/packed_doubles.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace mbopt::packed {
namespace {

// Bit for bit: == would call -0.0 and 0.0 equal and NaN unequal to itself.
void ExpectSameBits(const std::vector<double>& expected, const std::vector<double>& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    ASSERT_EQ(std::bit_cast<std::uint64_t>(expected[i]), std::bit_cast<std::uint64_t>(actual[i])) << "value " << i;
  }
}

std::vector<double> RoundTrip(const std::vector<double>& values) {
  const std::string packed = PackDoubles(values);
  absl::StatusOr<std::vector<double>> unpacked = UnpackDoubles(packed, values.size());
  EXPECT_TRUE(unpacked.ok()) << unpacked.status();
  return unpacked.ok() ? *unpacked : std::vector<double>{};
}

// Rows as a study makes them from a MAX_ABS output: f(t_i), -f(t_i), ...
std::vector<double> MaxAbsRows(int instants) {
  std::vector<double> rows;
  for (int i = 0; i < instants; ++i) {
    const double t = 5.0 * i / (instants - 1);
    const double f = 0.02 * std::exp(-0.4 * t) * std::sin(7.3 * t) + 1e-3 * std::cos(1.1 * t);
    rows.push_back(f);
    rows.push_back(-f);
  }
  return rows;
}

TEST(PackedDoubles, SpecialValuesComeBackBitForBit) {
  const double qnan_payload = std::bit_cast<double>(std::uint64_t{0x7FF8'0000'0000'1234});
  const double snan = std::bit_cast<double>(std::uint64_t{0x7FF0'0000'0000'0001});
  ExpectSameBits({0.0, -0.0, -0.0, 0.0, std::numeric_limits<double>::infinity(),
                  -std::numeric_limits<double>::infinity(), qnan_payload, snan,
                  std::numeric_limits<double>::denorm_min(), -std::numeric_limits<double>::denorm_min(),
                  std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest(), 1.0, -1.0, -1.0, 1.0},
                 RoundTrip({0.0, -0.0, -0.0, 0.0, std::numeric_limits<double>::infinity(),
                            -std::numeric_limits<double>::infinity(), qnan_payload, snan,
                            std::numeric_limits<double>::denorm_min(), -std::numeric_limits<double>::denorm_min(),
                            std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest(), 1.0, -1.0,
                            -1.0, 1.0}));
}

TEST(PackedDoubles, EmptyAndSingleValues) {
  ExpectSameBits({}, RoundTrip({}));
  ExpectSameBits({-2.5}, RoundTrip({-2.5}));
}

TEST(PackedDoubles, RandomBitPatternsOfManyBlocksRoundTrip) {
  std::mt19937_64 random(7);
  std::vector<double> values;
  for (int i = 0; i < 5000; ++i) {
    const std::uint64_t bits = random();
    values.push_back(std::bit_cast<double>(bits));
    if (bits % 3 == 0) values.push_back(-values.back());  // some negation pairs, not all
  }
  ExpectSameBits(values, RoundTrip(values));
}

TEST(PackedDoubles, SmoothSeriesOfMaxAbsRowsPackTenfold) {
  const std::vector<double> rows = MaxAbsRows(30001);
  const std::string packed = PackDoubles(rows);
  ExpectSameBits(rows, RoundTrip(rows));
  // 8 bytes a value unpacked; the negations cost a bit each and the smooth
  // series leave residuals of a few bits.
  EXPECT_LT(packed.size() * 10, rows.size() * sizeof(double)) << packed.size() << " bytes";
}

// A cheap analysis' few values are stored (byte 1 of the packing: 0), not
// deflated: deflate's set-up would cost more than the analysis. A fine grid's
// are deflated (1).
TEST(PackedDoubles, SmallPayloadsAreStoredAndLargeOnesDeflated) {
  const std::vector<double> few = MaxAbsRows(20);
  const std::string small = PackDoubles(few);
  ASSERT_GT(small.size(), 2u);
  EXPECT_EQ(small[1], 0);
  EXPECT_LT(small.size(), few.size() * sizeof(double));
  ExpectSameBits(few, RoundTrip(few));
  const std::string large = PackDoubles(MaxAbsRows(30001));
  EXPECT_EQ(large[1], 1);
}

TEST(PackedDoubles, RefusesMoreValuesThanTheCallerExpects) {
  const std::string packed = PackDoubles(MaxAbsRows(100));
  const absl::StatusOr<std::vector<double>> unpacked = UnpackDoubles(packed, 199);
  ASSERT_FALSE(unpacked.ok());
  EXPECT_NE(unpacked.status().message().find("200 values, at most 199"), std::string::npos) << unpacked.status();
}

TEST(PackedDoubles, RefusesDamagedOrForeignBytes) {
  const std::vector<double> rows = MaxAbsRows(300);
  const std::string packed = PackDoubles(rows);
  EXPECT_FALSE(UnpackDoubles("", 10).ok());
  EXPECT_FALSE(UnpackDoubles(std::string(8, '\0'), 10).ok());                    // raw doubles, not a packing
  EXPECT_FALSE(UnpackDoubles(packed.substr(0, packed.size() - 3), 600).ok());  // truncated
  EXPECT_FALSE(UnpackDoubles(packed + "x", 600).ok());                          // trailing bytes
  std::string other_version = packed;
  other_version[0] = 2;
  EXPECT_FALSE(UnpackDoubles(other_version, 600).ok());
  // Every single-byte change of the header or the payload is refused or
  // gives some values: never a crash or an allocation past the bound.
  for (std::size_t at = 0; at < packed.size(); ++at) {
    std::string damaged = packed;
    damaged[at] = static_cast<char>(damaged[at] ^ 0x5A);
    const absl::StatusOr<std::vector<double>> unpacked = UnpackDoubles(damaged, 600);
    if (unpacked.ok()) {
      EXPECT_EQ(unpacked->size(), 600u);
    }
  }
}

TEST(PackedDoubles, RefusesAClaimOfMoreValuesThanTheBytesCanHold) {
  // A header claiming 10^9 values over a few bytes: refused before any
  // allocation, even when the caller's bound allows it.
  std::string packed = PackDoubles(std::vector<double>{1.0, 2.0});
  for (int b = 0; b < 8; ++b) packed[1 + static_cast<std::size_t>(b)] = static_cast<char>((1'000'000'000ull >> (8 * b)) & 0xFF);
  for (int b = 0; b < 8; ++b) packed[9 + static_cast<std::size_t>(b)] = static_cast<char>((1'000'000'000ull >> (8 * b)) & 0xFF);
  const absl::StatusOr<std::vector<double>> unpacked = UnpackDoubles(packed, 2'000'000'000);
  ASSERT_FALSE(unpacked.ok());
  EXPECT_NE(unpacked.status().message().find("cannot hold"), std::string::npos) << unpacked.status();
}

}  // namespace
}  // namespace mbopt::packed
