// What a study needs to know of an FMU archive it carries, read from its
// bytes: whether it is a zip archive at all, its SHA-256 (what workers cache
// the unpacked archive under) and the platforms it has binaries for
// (`binaries/<platform>/...`), which the server matches against the
// platforms its workers load. Nothing is unpacked here.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace mbopt::spec::io {

// The bytes of the FMU file at `path`; InvalidArgument naming it when it
// cannot be read or is larger than kMaxFmuArchiveBytes.
absl::StatusOr<std::string> ReadFmuArchive(const std::filesystem::path& path);

struct FmuArchiveContents {
  std::string sha256;                  // lowercase hex
  std::vector<std::string> platforms;  // sorted, unique
};

// InvalidArgument when `bytes` are not a zip archive.
absl::StatusOr<FmuArchiveContents> ReadFmuArchiveContents(const std::string& bytes);

}  // namespace mbopt::spec::io
