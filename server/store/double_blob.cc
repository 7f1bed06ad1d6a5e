#include "server/store/double_blob.h"

#include <cstdint>
#include <cstring>

#include "absl/strings/str_cat.h"

namespace mbopt::store {

std::string EncodeDoubles(const std::vector<double>& values) {
  std::string blob(values.size() * 8, '\0');
  for (size_t i = 0; i < values.size(); ++i) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &values[i], sizeof bits);
    for (int b = 0; b < 8; ++b) {
      blob[i * 8 + static_cast<size_t>(b)] = static_cast<char>((bits >> (8 * b)) & 0xffu);
    }
  }
  return blob;
}

absl::StatusOr<std::vector<double>> DecodeDoubles(const std::string& blob) {
  if (blob.size() % 8 != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("a blob of doubles has ", blob.size(), " bytes, not a multiple of 8"));
  }
  std::vector<double> values(blob.size() / 8);
  for (size_t i = 0; i < values.size(); ++i) {
    std::uint64_t bits = 0;
    for (int b = 0; b < 8; ++b) {
      bits |= static_cast<std::uint64_t>(static_cast<unsigned char>(blob[i * 8 + static_cast<size_t>(b)]))
              << (8 * b);
    }
    std::memcpy(&values[i], &bits, sizeof bits);
  }
  return values;
}

}  // namespace mbopt::store
