// libFuzzer target: a result's packed values (tests/fuzz/README.md).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "tests/fuzz/fuzz_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  mbopt::fuzz::CheckPackedValues(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
