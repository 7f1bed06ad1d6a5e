// libFuzzer target: a batch of results as a hostile worker could send it
// (tests/fuzz/README.md).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "tests/fuzz/result_intake_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  mbopt::fuzz::CheckResultIntake(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
