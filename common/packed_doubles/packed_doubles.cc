#include "common/packed_doubles/packed_doubles.h"

#include <zlib.h>

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>

#include "absl/strings/str_cat.h"

namespace mbopt::packed {
namespace {

constexpr unsigned char kVersion = 1;
// How the payload follows the header.
constexpr unsigned char kStored = 0;
constexpr unsigned char kDeflated = 1;
constexpr std::size_t kHeaderBytes = 1 + 1 + 8 + 8;
// Smaller payloads are stored as they are: deflate's set-up alone (about
// 0.1 ms) would cost more than a cheap analysis' result is worth, and the
// byte widths already take a smooth series to a third or so.
constexpr std::size_t kDeflateFromBytes = 16 * 1024;
constexpr std::size_t kBlock = 1024;
constexpr int kMaxOrder = 5;
constexpr std::uint64_t kSign = std::uint64_t{1} << 63;
// Level 1: on the 30,001-instant vehicle's rows the default level 6 packed
// about 5 % smaller in twice the time; the worker packs every result it sends.
constexpr int kDeflateLevel = 1;
// Deflate expands at most about 1032x; a larger claim is not a packing.
constexpr std::size_t kMaxInflateRatio = 1100;

// Coefficients of the extrapolation of order k from the k values before:
// row k of (1 - z)^k - 1, i.e. binomial coefficients with alternating sign.
constexpr std::array<std::array<std::int64_t, kMaxOrder>, kMaxOrder + 1> kCoefficients = {{
    {0, 0, 0, 0, 0},
    {1, 0, 0, 0, 0},
    {2, -1, 0, 0, 0},
    {3, -3, 1, 0, 0},
    {4, -6, 4, -1, 0},
    {5, -10, 10, -5, 1},
}};

// Monotone in the double's value and continuous through zero (-0.0 and +0.0
// are neighbours), so smooth series stay smooth as integers.
std::uint64_t KeyOf(double value) {
  const std::uint64_t bits = std::bit_cast<std::uint64_t>(value);
  return (bits & kSign) != 0 ? ~bits : bits | kSign;
}
double ValueOf(std::uint64_t key) { return std::bit_cast<double>((key & kSign) != 0 ? key & ~kSign : ~key); }

std::uint64_t ZigZag(std::uint64_t residual) {
  return (residual << 1) ^ static_cast<std::uint64_t>(static_cast<std::int64_t>(residual) >> 63);
}
std::uint64_t UnZigZag(std::uint64_t z) { return (z >> 1) ^ (std::uint64_t{0} - (z & 1)); }

// Prediction of keys[i] by extrapolation of order `order` (fewer at the
// start), modulo 2^64.
std::uint64_t Predict(const std::vector<std::uint64_t>& keys, std::size_t i, int order) {
  const int k = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(order), i));
  std::uint64_t p = 0;
  for (int j = 0; j < k; ++j) {
    p += static_cast<std::uint64_t>(kCoefficients[static_cast<std::size_t>(k)][static_cast<std::size_t>(j)]) *
         keys[i - 1 - static_cast<std::size_t>(j)];
  }
  return p;
}

void PutU64(std::string& out, std::uint64_t v) {
  for (int b = 0; b < 8; ++b) out.push_back(static_cast<char>((v >> (8 * b)) & 0xFF));
}
std::uint64_t GetU64(std::string_view in, std::size_t at) {
  std::uint64_t v = 0;
  for (int b = 0; b < 8; ++b) v |= std::uint64_t{static_cast<unsigned char>(in[at + static_cast<std::size_t>(b)])} << (8 * b);
  return v;
}

std::size_t Blocks(std::size_t kept) { return (kept + kBlock - 1) / kBlock; }

}  // namespace

std::string PackDoubles(std::span<const double> values) {
  const std::size_t n = values.size();
  std::vector<unsigned char> flags((n + 7) / 8, 0);
  std::vector<std::uint64_t> keys;
  keys.reserve(n);
  bool previous_flagged = true;  // the first value is always kept
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t bits = std::bit_cast<std::uint64_t>(values[i]);
    if (!previous_flagged && bits == (std::bit_cast<std::uint64_t>(values[i - 1]) ^ kSign)) {
      flags[i / 8] = static_cast<unsigned char>(flags[i / 8] | (1u << (i % 8)));
      previous_flagged = true;
      continue;
    }
    previous_flagged = false;
    keys.push_back(KeyOf(values[i]));
  }
  const std::size_t kept = keys.size();
  const std::size_t blocks = Blocks(kept);

  // Payload: the flags; per block its order and byte width; then per block
  // its residuals' byte planes up to that width (a block of smooth values
  // needs two or three of the eight).
  std::string payload(flags.begin(), flags.end());
  payload.resize(flags.size() + 2 * blocks);
  payload.reserve(flags.size() + 2 * blocks + 3 * kept);
  // The residual of the order-k extrapolation is the k-th backward
  // difference (exactly, modulo 2^64), so all orders cost a few subtractions
  // a value; the decoder's Predict gives the same integers.
  std::array<std::uint64_t, kMaxOrder + 1> previous{};
  std::vector<std::array<std::uint64_t, kMaxOrder + 1>> residuals(std::min(kept, kBlock));
  for (std::size_t block = 0; block < blocks; ++block) {
    const std::size_t begin = block * kBlock;
    const std::size_t end = std::min(kept, begin + kBlock);
    std::array<std::uint64_t, kMaxOrder + 1> bits{};
    for (std::size_t i = begin; i < end; ++i) {
      std::array<std::uint64_t, kMaxOrder + 1> difference;
      difference[0] = keys[i];
      for (int k = 1; k <= kMaxOrder; ++k) difference[k] = difference[k - 1] - previous[k - 1];
      previous = difference;
      auto& r = residuals[i - begin];
      for (int k = 0; k <= kMaxOrder; ++k) {
        // Fewer values before than the order: the order the decoder uses.
        r[k] = ZigZag(difference[std::min<std::size_t>(static_cast<std::size_t>(k), i)]);
        bits[k] += static_cast<std::uint64_t>(std::bit_width(r[k]));
      }
    }
    // The order with the fewest significant bits over the block.
    int best_order = 0;
    for (int k = 1; k <= kMaxOrder; ++k) {
      if (bits[k] < bits[best_order]) best_order = k;
    }
    std::uint64_t all = 0;
    for (std::size_t i = begin; i < end; ++i) all |= residuals[i - begin][best_order];
    const std::size_t width = (static_cast<std::size_t>(std::bit_width(all)) + 7) / 8;
    payload[flags.size() + 2 * block] = static_cast<char>(best_order);
    payload[flags.size() + 2 * block + 1] = static_cast<char>(width);
    for (std::size_t b = 0; b < width; ++b) {
      for (std::size_t i = begin; i < end; ++i) {
        payload.push_back(static_cast<char>((residuals[i - begin][best_order] >> (8 * b)) & 0xFF));
      }
    }
  }

  std::string out(1, static_cast<char>(kVersion));
  const bool deflate = payload.size() >= kDeflateFromBytes;
  out.push_back(static_cast<char>(deflate ? kDeflated : kStored));
  PutU64(out, n);
  PutU64(out, kept);
  if (!deflate) return out + payload;
  uLongf deflated_size = compressBound(static_cast<uLong>(payload.size()));
  out.resize(kHeaderBytes + deflated_size);
  const int z = compress2(reinterpret_cast<Bytef*>(out.data() + kHeaderBytes), &deflated_size,
                          reinterpret_cast<const Bytef*>(payload.data()), static_cast<uLong>(payload.size()),
                          kDeflateLevel);
  // compress2 into compressBound bytes fails only without memory.
  if (z != Z_OK) throw std::bad_alloc();
  out.resize(kHeaderBytes + deflated_size);
  return out;
}

absl::StatusOr<std::vector<double>> UnpackDoubles(std::string_view packed, std::size_t max_values) {
  if (packed.size() < kHeaderBytes || static_cast<unsigned char>(packed[0]) != kVersion ||
      static_cast<unsigned char>(packed[1]) > kDeflated) {
    return absl::InvalidArgumentError("packed values: not version 1 (bad header)");
  }
  const bool deflated = static_cast<unsigned char>(packed[1]) == kDeflated;
  const std::uint64_t n = GetU64(packed, 2);
  const std::uint64_t kept = GetU64(packed, 10);
  if (n > max_values) {
    return absl::InvalidArgumentError(absl::StrCat("packed values: ", n, " values, at most ", max_values, " expected"));
  }
  // No flag follows a flag, so at least half the values are kept.
  if (kept > n || kept < n - n / 2) {
    return absl::InvalidArgumentError(absl::StrCat("packed values: ", kept, " of ", n, " kept"));
  }
  const std::size_t flag_bytes = (n + 7) / 8;
  const std::size_t blocks = Blocks(kept);
  const std::size_t heads = flag_bytes + 2 * blocks;  // the least a payload holds
  const std::string_view body = packed.substr(kHeaderBytes);
  if (heads > (deflated ? kMaxInflateRatio : 1) * body.size()) {
    return absl::InvalidArgumentError(absl::StrCat("packed values: ", packed.size(), " bytes cannot hold ", n,
                                                   " values"));
  }
  std::string inflated_payload;
  std::string_view payload = body;
  if (deflated) {
    // Deflate cannot expand more than kMaxInflateRatio: no need for more room.
    const std::size_t room = std::min(heads + 8 * kept, kMaxInflateRatio * body.size());
    inflated_payload.assign(room, '\0');
    uLongf inflated = static_cast<uLongf>(room);
    uLong consumed = static_cast<uLong>(body.size());
    const int z = uncompress2(reinterpret_cast<Bytef*>(inflated_payload.data()), &inflated,
                              reinterpret_cast<const Bytef*>(body.data()), &consumed);
    if (z != Z_OK || consumed != body.size()) {
      return absl::InvalidArgumentError("packed values: the deflated payload is damaged or of the wrong size");
    }
    payload = std::string_view(inflated_payload).substr(0, inflated);
  }
  if (payload.size() < heads) return absl::InvalidArgumentError("packed values: the payload is too short");
  const auto* flags = reinterpret_cast<const unsigned char*>(payload.data());
  const unsigned char* block_heads = flags + flag_bytes;
  std::size_t expected = heads;
  for (std::size_t block = 0; block < blocks; ++block) {
    if (block_heads[2 * block] > kMaxOrder || block_heads[2 * block + 1] > 8) {
      return absl::InvalidArgumentError("packed values: bad predictor order or width");
    }
    expected += block_heads[2 * block + 1] * (std::min(kept, (block + 1) * kBlock) - block * kBlock);
  }
  if (payload.size() != expected) {
    return absl::InvalidArgumentError(
        absl::StrCat("packed values: a payload of ", payload.size(), " bytes where ", expected, " were expected"));
  }
  std::vector<std::uint64_t> keys(kept);
  const unsigned char* planes = block_heads + 2 * blocks;
  for (std::size_t block = 0; block < blocks; ++block) {
    const std::size_t begin = block * kBlock;
    const std::size_t length = std::min(kept, begin + kBlock) - begin;
    const int order = block_heads[2 * block];
    const std::size_t width = block_heads[2 * block + 1];
    for (std::size_t i = begin; i < begin + length; ++i) {
      std::uint64_t zz = 0;
      for (std::size_t b = 0; b < width; ++b) zz |= std::uint64_t{planes[b * length + (i - begin)]} << (8 * b);
      keys[i] = Predict(keys, i, order) + UnZigZag(zz);
    }
    planes += width * length;
  }
  std::vector<double> values;
  values.reserve(n);
  std::size_t next_key = 0;
  bool previous_flagged = true;
  for (std::size_t i = 0; i < n; ++i) {
    const bool flagged = ((flags[i / 8] >> (i % 8)) & 1) != 0;
    if (flagged) {
      if (previous_flagged) return absl::InvalidArgumentError("packed values: a negation flag without its value");
      values.push_back(std::bit_cast<double>(std::bit_cast<std::uint64_t>(values.back()) ^ kSign));
    } else {
      if (next_key == kept) return absl::InvalidArgumentError("packed values: more values flagged kept than stored");
      values.push_back(ValueOf(keys[next_key++]));
    }
    previous_flagged = flagged;
  }
  if (next_key != kept) return absl::InvalidArgumentError("packed values: fewer values flagged kept than stored");
  return values;
}

}  // namespace mbopt::packed
