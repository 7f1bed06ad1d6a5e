#include "worker/fmu/private_binary_copy.h"

#include <stdlib.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace mbopt::fmu {

absl::StatusOr<PrivateBinaryCopy> PrivateBinaryCopy::Make(const std::filesystem::path& binary) {
  const std::string suffix = binary.extension().string();
  // mkstemps replaces the six X with a unique name part and creates the file.
  std::string name_template =
      (binary.parent_path() / absl::StrCat(binary.stem().string(), ".instance-XXXXXX", suffix)).string();
  const int descriptor = mkstemps(name_template.data(), static_cast<int>(suffix.size()));
  if (descriptor < 0) {
    return absl::FailedPreconditionError(absl::StrCat(
        binary.string(), ": the FMU can be instantiated only once per process, and no private copy of its binary "
                         "could be made in its folder: ", std::strerror(errno)));
  }
  close(descriptor);
  PrivateBinaryCopy copy{std::filesystem::path(name_template)};
  std::error_code error;
  std::filesystem::copy_file(binary, copy.path_, std::filesystem::copy_options::overwrite_existing, error);
  if (error) {
    return absl::FailedPreconditionError(
        absl::StrCat(binary.string(), ": copying the binary for a private instance failed: ", error.message()));
  }
  return copy;
}

PrivateBinaryCopy::PrivateBinaryCopy(PrivateBinaryCopy&& other) noexcept : path_(std::move(other.path_)) {
  other.path_.clear();
}

PrivateBinaryCopy::~PrivateBinaryCopy() {
  if (path_.empty()) return;
  std::error_code ignored;
  std::filesystem::remove(path_, ignored);
}

}  // namespace mbopt::fmu
