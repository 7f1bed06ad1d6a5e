#include "client/temp_dir.h"

#include <stdlib.h>

#include <filesystem>
#include <system_error>

namespace mbopt::client {

TempDir::TempDir() {
  std::error_code ec;
  const std::filesystem::path base = std::filesystem::temp_directory_path(ec);
  // mkdtemp's template: it replaces the trailing XXXXXX with a unique name.
  std::string pattern = ((ec ? std::filesystem::path("/tmp") : base) / "mbopt-XXXXXX").string();
  if (mkdtemp(pattern.data()) != nullptr) path_ = pattern;
}

TempDir::~TempDir() {
  if (path_.empty()) return;
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

}  // namespace mbopt::client
