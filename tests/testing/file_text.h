// A file's whole text, for tests that read the examples' scenes and studies.
#pragma once

#include <fstream>
#include <sstream>
#include <string>

namespace mbopt::testing {

// The text of the file at `path` (relative paths from the working
// directory: the tests run from the source tree); "" when it cannot be read.
inline std::string FileText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace mbopt::testing
