// Vectors of doubles as database blobs, bit for bit: each value is its IEEE
// 754 binary64 pattern in little-endian byte order, whatever the host, so a
// value read back is the identical double (NaN payloads and -0.0 included).
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace mbopt::store {

std::string EncodeDoubles(const std::vector<double>& values);

// InvalidArgument when the blob length is not a multiple of 8.
absl::StatusOr<std::vector<double>> DecodeDoubles(const std::string& blob);

}  // namespace mbopt::store
