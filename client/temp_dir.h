// A private temporary directory (mode 0700, under $TMPDIR), removed with its
// contents when the object goes away: the port file, logs and databases
// of servers the CLI starts for one command.
#pragma once

#include <string>

namespace mbopt::client {

class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  // Empty if the directory could not be made.
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace mbopt::client
