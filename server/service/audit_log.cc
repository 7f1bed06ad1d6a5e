#include "server/service/audit_log.h"

#include <unistd.h>

#include <cerrno>
#include <string>

namespace mbopt::service {

void AuditLog(std::string_view line) {
  std::string text = "mbopt-server: audit: ";
  text.append(line);
  // One line each: a message with a newline of its own would start a line
  // that looks like another entry.
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  text += '\n';
  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(STDERR_FILENO, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // no log to write to: nothing else to do
    written += static_cast<std::size_t>(n);
  }
}

}  // namespace mbopt::service
