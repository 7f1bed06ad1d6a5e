// The path rules of drivers: a declared path is relative, has no ".." and
// leads (links resolved) nowhere outside the directory it is relative to.
// Checked when declarations are read and again when an analysis copies its
// files, since a link may change in between.
#pragma once

#include <filesystem>
#include <string>

#include "absl/status/status.h"

namespace mbopt::external {

// OK when `relative` is a non-empty relative path without "." or ".."
// components; otherwise InvalidArgument saying what is wrong (`what` names
// the path in the message, e.g. "file \"x\"").
absl::Status CheckRelativePath(const std::string& relative, const std::string& what);

// True when `path`, with every link resolved, is `directory` or lies below
// it. `directory` must be canonical. False when `path` cannot be resolved.
bool ResolvesInside(const std::filesystem::path& path, const std::filesystem::path& directory);

// A name usable in a file name: letters, digits, '_', '-', '.', not starting
// with '.', 1 to 100 characters (driver names and analysis ids).
bool IsSafeName(const std::string& name);

}  // namespace mbopt::external
