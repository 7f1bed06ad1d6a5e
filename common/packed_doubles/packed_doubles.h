// Vectors of doubles packed losslessly for the wire and the job database: a
// value unpacked is the identical double (bit pattern, -0.0 and NaN payloads
// included), on any host.
//
// An analysis' values are mostly time series sampled finely (one row per
// grid instant), and a MAX_ABS output gives each value twice, f and -f. So:
//  1. a value that is exactly the negation of the one before it (and that one
//     is kept) is dropped and flagged in a bitmap;
//  2. each kept value's bit pattern is mapped to an integer that is monotone
//     in the value and continuous through zero, and predicted by polynomial
//     extrapolation of order 0..5 from the values before it, in integer
//     arithmetic modulo 2^64 (no floating point, so every host predicts the
//     same); the order is chosen per block of 1024 values as the one with the
//     fewest significant residual bits;
//  3. the residuals, zigzag-coded, are split into their 8 byte planes and
//     the bitmap, the orders and the planes are deflated (zlib).
// On the vehicle study with 30,001 instants this is about 10x smaller than 8
// bytes a value (docs/store.md, "How values are stored").
//
// Layout, version 1 (little-endian): a byte 0x01; the number of values, 8
// bytes; the number kept, 8 bytes; then the deflated payload: the flag
// bitmap (ceil(values / 8) bytes, bit i % 8 of byte i / 8), one order byte
// per block of 1024 kept values, and the 8 planes of kept bytes each.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"

namespace mbopt::packed {

std::string PackDoubles(std::span<const double> values);

// InvalidArgument for bytes that are not a packing of version 1, or of more
// than `max_values` values (a bound the caller knows, e.g. the rows a study
// has: so a hostile packing cannot make it allocate more).
absl::StatusOr<std::vector<double>> UnpackDoubles(std::string_view packed, std::size_t max_values);

}  // namespace mbopt::packed
