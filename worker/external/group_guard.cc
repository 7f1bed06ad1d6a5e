#include "worker/external/group_guard.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "absl/strings/str_cat.h"

namespace mbopt::external {
namespace {

constexpr char kReleased = 'r';

// Reads exactly `size` bytes; false on end-of-file or an error. Only
// async-signal-safe calls: it runs in the forked child of a threaded process.
bool ReadAll(int fd, void* data, size_t size) {
  char* at = static_cast<char*>(data);
  while (size > 0) {
    const ssize_t n = read(fd, at, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    at += n;
    size -= static_cast<size_t>(n);
  }
  return true;
}

// The guard's life, between fork and _exit: after fork in a threaded
// process only async-signal-safe calls are allowed (no allocation, no
// locks), so this is system calls only.
[[noreturn]] void GuardMain(int read_fd) {
  // Every other descriptor closed: in particular the write ends of other
  // analyses' guards, which would otherwise keep their pipes open.
  if (read_fd > 3) syscall(SYS_close_range, 3u, static_cast<unsigned>(read_fd - 1), 0u);
  syscall(SYS_close_range, static_cast<unsigned>(read_fd + 1), ~0u, 0u);
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  for (int signal : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) sigaction(signal, &ignore, nullptr);
  pid_t group = 0;
  if (!ReadAll(read_fd, &group, sizeof group)) _exit(0);  // no driver was started
  char released = 0;
  if (ReadAll(read_fd, &released, 1) && released == kReleased) _exit(0);
  kill(-group, SIGKILL);
  _exit(0);
}

}  // namespace

absl::StatusOr<GroupGuard> GroupGuard::Start() {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    return absl::UnavailableError(absl::StrCat("cannot make the driver's guard pipe: ", std::strerror(errno)));
  }
  const pid_t pid = fork();
  if (pid < 0) {
    const int error = errno;
    close(fds[0]);
    close(fds[1]);
    return absl::UnavailableError(absl::StrCat("cannot start the driver's guard: ", std::strerror(error)));
  }
  if (pid == 0) GuardMain(fds[0]);
  close(fds[0]);
  return GroupGuard(pid, fds[1]);
}

GroupGuard::GroupGuard(GroupGuard&& other) noexcept : pid_(other.pid_), write_fd_(other.write_fd_) {
  other.pid_ = -1;
  other.write_fd_ = -1;
}

GroupGuard::~GroupGuard() { Release(); }

void GroupGuard::Watch(pid_t group) {
  if (write_fd_ < 0) return;
  // A pipe takes a write this small whole.
  (void)!write(write_fd_, &group, sizeof group);
}

void GroupGuard::Release() {
  if (write_fd_ >= 0) {
    (void)!write(write_fd_, &kReleased, 1);
    close(write_fd_);
    write_fd_ = -1;
  }
  if (pid_ > 0) {
    while (waitpid(pid_, nullptr, 0) < 0 && errno == EINTR) {
    }
    pid_ = -1;
  }
}

}  // namespace mbopt::external
