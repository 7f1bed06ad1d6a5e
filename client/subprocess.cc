#include "client/subprocess.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

extern char** environ;

namespace mbopt::client {
namespace {

using Clock = std::chrono::steady_clock;

int ExitCodeOf(int wait_status) {
  if (WIFEXITED(wait_status)) return WEXITSTATUS(wait_status);
  if (WIFSIGNALED(wait_status)) return 128 + WTERMSIG(wait_status);
  return -1;
}

int RemainingMs(Clock::time_point deadline) {
  auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
  return left.count() < 0 ? 0 : static_cast<int>(left.count());
}

absl::Status ErrnoStatus(const std::string& what) {
  return absl::InternalError(absl::StrCat(what, ": ", std::strerror(errno)));
}

}  // namespace

absl::StatusOr<Subprocess> Subprocess::Start(const std::vector<std::string>& argv,
                                             const SpawnOptions& options) {
  if (argv.empty()) return absl::InvalidArgumentError("empty command line");
  int out_pipe[2] = {-1, -1}, err_pipe[2] = {-1, -1};
  if (options.capture_stdout && pipe2(out_pipe, O_CLOEXEC) != 0) return ErrnoStatus("pipe");
  if (options.capture_stderr && pipe2(err_pipe, O_CLOEXEC) != 0) return ErrnoStatus("pipe");

  // Everything the child needs is prepared before fork: after fork only
  // async-signal-safe calls are allowed (the parent has gRPC threads).
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  std::vector<std::string> env_strings;
  for (char** e = environ; *e != nullptr; ++e) env_strings.emplace_back(*e);
  for (const auto& e : options.extra_env) env_strings.push_back(e);
  std::vector<char*> env;
  for (auto& e : env_strings) env.push_back(e.data());
  env.push_back(nullptr);
  const pid_t parent = getpid();
  const char* stderr_path =
      options.stderr_path.empty() ? nullptr : options.stderr_path.c_str();

  pid_t pid = fork();
  if (pid < 0) return ErrnoStatus("fork");
  if (pid == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);  // the parent died before prctl
    int devnull = open("/dev/null", O_RDWR | O_CLOEXEC);
    int err_file = stderr_path == nullptr
                       ? -1
                       : open(stderr_path, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (options.capture_stdout) dup2(out_pipe[1], 1);
    else if (options.silence_stdout) dup2(devnull, 1);
    if (options.capture_stderr) dup2(err_pipe[1], 2);
    else if (err_file >= 0) dup2(err_file, 2);
    else if (options.silence_stderr) dup2(devnull, 2);
    // Signal dispositions and masks survive exec; give the child defaults.
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    signal(SIGPIPE, SIG_DFL);
    execve(args[0], args.data(), env.data());
    const char msg[] = "cannot execute ";
    [[maybe_unused]] ssize_t n = write(2, msg, sizeof msg - 1);
    n = write(2, args[0], std::strlen(args[0]));
    n = write(2, "\n", 1);
    _exit(127);
  }
  Subprocess p;
  p.pid_ = pid;
  p.pidfd_ = static_cast<int>(syscall(SYS_pidfd_open, pid, 0));
  if (p.pidfd_ < 0) return ErrnoStatus("pidfd_open");
  if (options.capture_stdout) {
    close(out_pipe[1]);
    p.stdout_fd_ = out_pipe[0];
  }
  if (options.capture_stderr) {
    close(err_pipe[1]);
    p.stderr_fd_ = err_pipe[0];
  }
  return p;
}

Subprocess::Subprocess(Subprocess&& other) noexcept { *this = std::move(other); }

Subprocess& Subprocess::operator=(Subprocess&& other) noexcept {
  if (this != &other) {
    pid_ = std::exchange(other.pid_, -1);
    pidfd_ = std::exchange(other.pidfd_, -1);
    stdout_fd_ = std::exchange(other.stdout_fd_, -1);
    stderr_fd_ = std::exchange(other.stderr_fd_, -1);
    stdout_buffer_ = std::move(other.stdout_buffer_);
    exit_status_ = std::exchange(other.exit_status_, std::nullopt);
  }
  return *this;
}

Subprocess::~Subprocess() {
  if (pid_ > 0 && running()) {
    kill(pid_, SIGKILL);
    int status = 0;
    waitpid(pid_, &status, 0);
  }
  CloseFds();
}

void Subprocess::CloseFds() {
  for (int* fd : {&pidfd_, &stdout_fd_, &stderr_fd_}) {
    if (*fd >= 0) close(*fd);
    *fd = -1;
  }
}

bool Subprocess::TryReap() {
  if (!running()) return true;
  int status = 0;
  pid_t r = waitpid(pid_, &status, WNOHANG);
  if (r == pid_) {
    exit_status_ = ExitCodeOf(status);
    return true;
  }
  return false;
}

void Subprocess::Signal(int signal_number) {
  if (pid_ > 0 && running()) kill(pid_, signal_number);
}

absl::StatusOr<int> Subprocess::Wait(std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (!TryReap()) {
    pollfd p{pidfd_, POLLIN, 0};
    int r = poll(&p, 1, RemainingMs(deadline));
    if (r == 0) return absl::DeadlineExceededError(absl::StrCat("process ", pid_, " still running"));
    if (r < 0 && errno != EINTR) return ErrnoStatus("poll");
  }
  return *exit_status_;
}

int Subprocess::Stop(std::chrono::milliseconds grace) {
  if (!running()) return *exit_status_;
  Signal(SIGTERM);
  auto code = Wait(grace);
  if (code.ok()) return *code;
  Signal(SIGKILL);
  return Wait(std::chrono::hours(1)).value_or(-1);
}

absl::StatusOr<std::string> Subprocess::ReadStdoutLine(std::chrono::milliseconds timeout) {
  if (stdout_fd_ < 0) return absl::FailedPreconditionError("stdout is not captured");
  const auto deadline = Clock::now() + timeout;
  while (true) {
    auto nl = stdout_buffer_.find('\n');
    if (nl != std::string::npos) {
      std::string line = stdout_buffer_.substr(0, nl);
      stdout_buffer_.erase(0, nl + 1);
      return line;
    }
    pollfd p{stdout_fd_, POLLIN, 0};
    int r = poll(&p, 1, RemainingMs(deadline));
    if (r == 0) return absl::DeadlineExceededError("no line on stdout in time");
    if (r < 0) {
      if (errno == EINTR) continue;
      return ErrnoStatus("poll");
    }
    char buf[4096];
    ssize_t n = read(stdout_fd_, buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      return ErrnoStatus("read");
    }
    if (n == 0) return absl::OutOfRangeError("stdout closed: " + stdout_buffer_);
    stdout_buffer_.append(buf, static_cast<size_t>(n));
  }
}

absl::StatusOr<Subprocess::Output> Subprocess::Communicate(std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  Output out;
  out.stdout_text = std::move(stdout_buffer_);
  stdout_buffer_.clear();
  while (stdout_fd_ >= 0 || stderr_fd_ >= 0) {
    pollfd fds[2];
    int n = 0;
    if (stdout_fd_ >= 0) fds[n++] = {stdout_fd_, POLLIN, 0};
    if (stderr_fd_ >= 0) fds[n++] = {stderr_fd_, POLLIN, 0};
    int r = poll(fds, static_cast<nfds_t>(n), RemainingMs(deadline));
    if (r == 0) {
      Signal(SIGKILL);
      (void)Wait(std::chrono::hours(1));
      return absl::DeadlineExceededError(absl::StrCat(
          "process did not finish in time; stdout so far:\n", out.stdout_text,
          "\nstderr so far:\n", out.stderr_text));
    }
    if (r < 0) {
      if (errno == EINTR) continue;
      return ErrnoStatus("poll");
    }
    for (int i = 0; i < n; ++i) {
      if (fds[i].revents == 0) continue;
      char buf[8192];
      ssize_t got = read(fds[i].fd, buf, sizeof buf);
      std::string& dest = fds[i].fd == stdout_fd_ ? out.stdout_text : out.stderr_text;
      if (got > 0) {
        dest.append(buf, static_cast<size_t>(got));
      } else if (got == 0 || errno != EINTR) {
        int& fd = fds[i].fd == stdout_fd_ ? stdout_fd_ : stderr_fd_;
        close(fd);
        fd = -1;
      }
    }
  }
  auto code = Wait(std::chrono::milliseconds(RemainingMs(deadline)));
  if (!code.ok()) {
    Signal(SIGKILL);
    (void)Wait(std::chrono::hours(1));
    return code.status();
  }
  out.exit_code = *code;
  return out;
}

absl::StatusOr<Subprocess::Output> RunCommand(const std::vector<std::string>& argv,
                                              std::chrono::milliseconds timeout,
                                              const std::vector<std::string>& extra_env) {
  SpawnOptions options;
  options.capture_stdout = true;
  options.capture_stderr = true;
  options.extra_env = extra_env;
  auto child = Subprocess::Start(argv, options);
  if (!child.ok()) return child.status();
  return child->Communicate(timeout);
}

}  // namespace mbopt::client
