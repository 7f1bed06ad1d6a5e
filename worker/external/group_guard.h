// Kills a driver's process group if this process dies while the group runs.
//
// The runner kills the group itself when the driver ends or times out, but a
// worker killed with SIGKILL (the out-of-memory killer, a scheduler's hard
// limit, `kill -9`) runs no code: its driver, in a process group of its own,
// would run on, orphaned, holding the machine's cores and its run folder.
// The guard is a small process forked before the driver starts. It waits on
// a pipe whose only writer is this process: a byte means the runner is done
// with the group (the guard leaves it alone); end-of-file without that byte
// means this process died, and the guard sends SIGKILL to the group.
//
// The guard ignores SIGINT, SIGTERM and SIGHUP, which reach it with the rest
// of this process' group (Ctrl-C in a terminal): the runner, not the guard,
// ends the driver in a graceful stop. Like the runner, it cannot reach a
// process that left the group (setsid).
#pragma once

#include <sys/types.h>

#include "absl/status/statusor.h"

namespace mbopt::external {

class GroupGuard {
 public:
  // Forks the guard; it waits for Watch's group or for this process' end.
  static absl::StatusOr<GroupGuard> Start();
  GroupGuard(GroupGuard&& other) noexcept;
  GroupGuard& operator=(GroupGuard&&) = delete;
  GroupGuard(const GroupGuard&) = delete;
  // Releases the guard (as Release) if still held.
  ~GroupGuard();

  // The process group to kill if this process dies; once.
  void Watch(pid_t group);
  // The runner is done with the group (it killed and reaped it): the guard
  // exits without a signal and is reaped.
  void Release();

  pid_t guard_pid() const { return pid_; }

 private:
  GroupGuard(pid_t pid, int write_fd) : pid_(pid), write_fd_(write_fd) {}

  pid_t pid_ = -1;
  int write_fd_ = -1;
};

}  // namespace mbopt::external
