#include "server/main/secret_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "absl/strings/str_cat.h"

namespace mbopt::server_main {
namespace {

absl::Status WriteAll(int fd, const std::string& path, const std::string& content) {
  std::size_t written = 0;
  while (written < content.size()) {
    const ssize_t n = ::write(fd, content.data() + written, content.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return absl::InternalError(absl::StrCat("cannot write ", path, ": ", std::strerror(errno)));
    written += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) return absl::InternalError(absl::StrCat("cannot sync ", path, ": ", std::strerror(errno)));
  return absl::OkStatus();
}

absl::Status OpenAndWrite(const std::string& path, const std::string& content, int flags, unsigned mode) {
  const int fd = ::open(path.c_str(), flags | O_WRONLY | O_CLOEXEC, mode);
  if (fd < 0) {
    if (errno == EEXIST) return absl::AlreadyExistsError(absl::StrCat(path, " exists already; not overwritten"));
    return absl::InternalError(absl::StrCat("cannot create ", path, ": ", std::strerror(errno)));
  }
  absl::Status status = WriteAll(fd, path, content);
  ::close(fd);
  return status;
}

}  // namespace

absl::Status WriteNewFile(const std::string& path, const std::string& content, unsigned mode) {
  return OpenAndWrite(path, content, O_CREAT | O_EXCL, mode);
}

absl::Status AppendToFile(const std::string& path, const std::string& line) {
  return OpenAndWrite(path, line, O_CREAT | O_APPEND, 0600);
}

}  // namespace mbopt::server_main
