// slp::CycleRecord as bytes, for the job database: a small versioned binary
// format (little-endian; doubles as their IEEE 754 bit patterns) so that a
// decoded record equals the original bit for bit and two encodings of equal
// records are equal bytes. Resume compares records by their encodings.
//
// Layout, version 1: a byte 0x01, then the fields of CycleRecord in
// declaration order; int as 4 bytes, int64 as 8, bool as 1, double as 8,
// string as a 4-byte length and the bytes, Eigen vector as a 4-byte length
// and the doubles, vector<bool> as a 4-byte length and one byte each.
#pragma once

#include <string>

#include "absl/status/statusor.h"
#include "server/slp/slp_optimizer.h"

namespace mbopt::jobs {

std::string EncodeCycleRecord(const slp::CycleRecord& record);
// DataLoss for bytes that are not a version-1 record.
absl::StatusOr<slp::CycleRecord> DecodeCycleRecord(const std::string& bytes);

}  // namespace mbopt::jobs
