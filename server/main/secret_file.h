// Files that hold keys and tokens: created new (never over an existing
// file) and readable by their owner only, from the first byte on.
#pragma once

#include <string>

#include "absl/status/status.h"

namespace mbopt::server_main {

// Creates `path` with `mode` (0600 for secrets, 0644 for certificates) and
// writes `content`. AlreadyExists when the file exists.
absl::Status WriteNewFile(const std::string& path, const std::string& content, unsigned mode);

// Appends `line` to `path` (created 0600 if missing).
absl::Status AppendToFile(const std::string& path, const std::string& line);

}  // namespace mbopt::server_main
