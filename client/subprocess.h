// Child processes for `mbopt run` (a server and local workers) and for the
// end-to-end tests. A child runs in its own process group, so a Ctrl-C at the
// terminal reaches only `mbopt`, which then stops its children in order; and
// it gets SIGTERM if the thread that started it dies, so a killed `mbopt`
// leaves no orphans. Waiting uses a pidfd with poll(): deadlines are failure
// guards, never sleeps.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace mbopt::client {

struct SpawnOptions {
  bool capture_stdout = false;  // else inherited
  bool capture_stderr = false;  // else inherited (or /dev/null, below)
  bool silence_stdout = false;  // send stdout to /dev/null
  bool silence_stderr = false;  // send stderr to /dev/null
  std::string stderr_path;      // if set: stderr appended to this file
  std::vector<std::string> extra_env;  // "NAME=value", added to the environment
};

class Subprocess {
 public:
  static absl::StatusOr<Subprocess> Start(const std::vector<std::string>& argv,
                                          const SpawnOptions& options = {});
  Subprocess(Subprocess&& other) noexcept;
  Subprocess& operator=(Subprocess&& other) noexcept;
  Subprocess(const Subprocess&) = delete;
  Subprocess& operator=(const Subprocess&) = delete;
  // Kills (SIGKILL) and reaps a child that is still running.
  ~Subprocess();

  pid_t pid() const { return pid_; }
  // The read end of captured stdout (-1 if not captured); stays owned here.
  int stdout_fd() const { return stdout_fd_; }
  bool running() const { return !exit_status_.has_value(); }

  // Reads one line of captured stdout (without the newline). DeadlineExceeded
  // after `timeout`; OutOfRange if stdout closed first.
  absl::StatusOr<std::string> ReadStdoutLine(std::chrono::milliseconds timeout);

  // Reads captured stdout and stderr until both close and waits for the exit.
  // DeadlineExceeded (and the child killed) after `timeout`.
  struct Output {
    int exit_code = -1;  // 128 + signal number if killed by a signal
    std::string stdout_text;
    std::string stderr_text;
  };
  absl::StatusOr<Output> Communicate(std::chrono::milliseconds timeout);

  void Signal(int signal_number);
  // Waits for the exit and returns the exit code (128 + signal if killed).
  // DeadlineExceeded after `timeout` (the child keeps running).
  absl::StatusOr<int> Wait(std::chrono::milliseconds timeout);
  // SIGTERM, wait up to `grace`, then SIGKILL and wait. Returns the exit code.
  int Stop(std::chrono::milliseconds grace);

 private:
  Subprocess() = default;
  void CloseFds();
  bool TryReap();

  pid_t pid_ = -1;
  int pidfd_ = -1;
  int stdout_fd_ = -1;
  int stderr_fd_ = -1;
  std::string stdout_buffer_;  // read but not yet returned by ReadStdoutLine
  std::optional<int> exit_status_;
};

// Runs a command to completion and returns its exit code and output.
absl::StatusOr<Subprocess::Output> RunCommand(const std::vector<std::string>& argv,
                                              std::chrono::milliseconds timeout,
                                              const std::vector<std::string>& extra_env = {});

}  // namespace mbopt::client
