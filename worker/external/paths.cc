#include "worker/external/paths.h"

#include <system_error>

#include "absl/strings/str_cat.h"

namespace mbopt::external {

absl::Status CheckRelativePath(const std::string& relative, const std::string& what) {
  if (relative.empty()) return absl::InvalidArgumentError(absl::StrCat(what, " is empty"));
  const std::filesystem::path path(relative);
  if (path.is_absolute()) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, " is absolute; expected a path relative to the driver's directory"));
  }
  for (const auto& part : path) {
    if (part == "..") {
      return absl::InvalidArgumentError(
          absl::StrCat(what, " contains \"..\"; declared paths stay inside the driver's directory"));
    }
    if (part == ".") {
      return absl::InvalidArgumentError(absl::StrCat(what, " contains \".\"; expected a plain relative path"));
    }
  }
  return absl::OkStatus();
}

bool ResolvesInside(const std::filesystem::path& path, const std::filesystem::path& directory) {
  std::error_code ec;
  const std::filesystem::path resolved = std::filesystem::canonical(path, ec);
  if (ec) return false;
  auto d = directory.begin();
  auto p = resolved.begin();
  for (; d != directory.end(); ++d, ++p) {
    if (p == resolved.end() || *p != *d) return false;
  }
  return true;
}

bool IsSafeName(const std::string& name) {
  if (name.empty() || name.size() > 100 || name[0] == '.') return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

}  // namespace mbopt::external
