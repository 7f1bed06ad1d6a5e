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
//  3. the residuals, zigzag-coded, are split into byte planes, only as many
//     per block as its largest residual needs; a payload of 16 KiB or more
//     is then deflated (zlib, level 1), a smaller one stored as it is
//     (deflate's set-up would cost more than a cheap analysis is worth).
// On the vehicle study with 30,001 instants this is about 9.5x smaller than
// 8 bytes a value (docs/store.md, "How values are stored").
//
// Layout, version 1 (little-endian): a byte 0x01; a byte 0 (payload stored)
// or 1 (deflated); the number of values, 8 bytes; the number kept, 8 bytes;
// then the payload: the flag bitmap (ceil(values / 8) bytes, bit i % 8 of
// byte i / 8); for each block of 1024 kept values (the last may be shorter)
// its order and its width w (0..8: the bytes its largest residual needs), a
// byte each; then for each block its w byte planes, lowest first, of one
// byte per value.
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
