#include "worker/external/runner.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/status_macros.h"
#include "worker/external/group_guard.h"
#include "worker/external/input_template.h"
#include "worker/external/paths.h"

extern char** environ;

namespace mbopt::external {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr char kStdoutFile[] = "driver.stdout";
constexpr char kStderrFile[] = "driver.stderr";
// Bytes read from the end of stderr for its last lines.
constexpr std::streamoff kStderrTailBytes = 8192;

std::string ErrnoText(int error) { return std::strerror(error); }

absl::Status CheckValues(const DriverDeclaration& driver, const std::map<std::string, double>& values) {
  std::vector<std::string> missing;
  for (const std::string& name : driver.parameters) {
    if (!values.contains(name)) missing.push_back(name);
  }
  if (!missing.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("driver '", driver.name, "': no value for parameter(s) ",
                                                   absl::StrJoin(missing, ", ")));
  }
  for (const auto& [name, value] : values) {
    if (std::find(driver.parameters.begin(), driver.parameters.end(), name) == driver.parameters.end()) {
      return absl::InvalidArgumentError(absl::StrCat("driver '", driver.name, "' has no parameter '", name,
                                                     "'; it declares: ", absl::StrJoin(driver.parameters, ", ")));
    }
    if (!std::isfinite(value)) {
      return absl::InvalidArgumentError(
          absl::StrCat("driver '", driver.name, "': parameter '", name, "' is not finite"));
    }
  }
  return absl::OkStatus();
}

// Copies `from` (a file or a directory, links followed) to `to`, refusing
// any link that resolves outside `base`.
absl::Status CopyInside(const fs::path& from, const fs::path& to, const fs::path& base,
                        const std::string& declared) {
  if (!ResolvesInside(from, base)) {
    return absl::FailedPreconditionError(absl::StrCat("driver file \"", declared, "\": ", from.string(),
                                                      " is missing or a link leading outside ",
                                                      base.string()));
  }
  std::error_code ec;
  const fs::file_status status = fs::status(from, ec);
  if (fs::is_directory(status)) {
    fs::create_directories(to, ec);
    if (ec) return absl::InternalError(absl::StrCat("cannot create ", to.string(), ": ", ec.message()));
    for (const auto& entry : fs::directory_iterator(from, ec)) {
      MBOPT_RETURN_IF_ERROR(CopyInside(entry.path(), to / entry.path().filename(), base, declared));
    }
    if (ec) return absl::InternalError(absl::StrCat("cannot list ", from.string(), ": ", ec.message()));
    return absl::OkStatus();
  }
  if (!fs::is_regular_file(status)) {
    return absl::FailedPreconditionError(
        absl::StrCat("driver file \"", declared, "\": ", from.string(), " is not a regular file or directory"));
  }
  fs::create_directories(to.parent_path(), ec);
  fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
  if (ec) {
    return absl::InternalError(
        absl::StrCat("cannot copy ", from.string(), " to ", to.string(), ": ", ec.message()));
  }
  // Scripts stay executable; nobody else gets access.
  fs::permissions(to, status.permissions() & fs::perms::owner_all, ec);
  return absl::OkStatus();
}

absl::Status WriteFile(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) return absl::InternalError(absl::StrCat("cannot write ", path.string()));
  return absl::OkStatus();
}

// The last `lines` lines of the file (at most kStderrTailBytes of it).
std::string TailLines(const fs::path& path, int lines) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(std::max<std::streamoff>(0, size - kStderrTailBytes));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  std::size_t start = text.size();
  for (int n = 0; n < lines; ++n) {
    const std::size_t newline = start == 0 ? std::string::npos : text.rfind('\n', start - 1);
    if (newline == std::string::npos) return text;
    start = newline;
  }
  return text.substr(start + 1);
}

// True when `marker` occurs in the file; read in blocks so a large output
// costs no memory.
bool FileContains(const fs::path& path, const std::string& marker) {
  if (marker.empty()) return false;
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  constexpr std::size_t kBlock = 1 << 16;
  std::string window;
  std::vector<char> block(kBlock);
  while (in) {
    in.read(block.data(), kBlock);
    window.append(block.data(), static_cast<std::size_t>(in.gcount()));
    if (window.find(marker) != std::string::npos) return true;
    // Keep what could be the start of a marker split across blocks.
    if (window.size() >= marker.size()) window.erase(0, window.size() - (marker.size() - 1));
  }
  return false;
}

struct Child {
  pid_t pid = -1;
  int pidfd = -1;  // -1 where the kernel has no pidfd_open
};

absl::StatusOr<Child> Spawn(const DriverDeclaration& driver, const fs::path& folder) {
  posix_spawn_file_actions_t actions;
  posix_spawnattr_t attributes;
  posix_spawn_file_actions_init(&actions);
  posix_spawnattr_init(&attributes);
  const std::string out_path = (folder / kStdoutFile).string();
  const std::string err_path = (folder / kStderrFile).string();
  posix_spawn_file_actions_addchdir_np(&actions, folder.c_str());
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  // A group of its own, so that the time limit reaches every process the
  // driver starts; signals as a fresh program expects them, whatever this
  // process blocks or ignores.
  sigset_t empty, all;
  sigemptyset(&empty);
  sigfillset(&all);
  sigdelset(&all, SIGKILL);
  sigdelset(&all, SIGSTOP);
  posix_spawnattr_setpgroup(&attributes, 0);
  posix_spawnattr_setsigmask(&attributes, &empty);
  posix_spawnattr_setsigdefault(&attributes, &all);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);

  std::vector<char*> argv;
  for (const std::string& arg : driver.command) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  // "./file" is relative to the analysis folder; posix_spawn resolves a
  // relative path against this process' directory, not the child's.
  std::string program = driver.command[0];
  if (program.rfind("./", 0) == 0) program = (folder / program.substr(2)).string();

  Child child;
  const int error = posix_spawn(&child.pid, program.c_str(), &actions, &attributes, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  if (error != 0) {
    return absl::FailedPreconditionError(
        absl::StrCat("driver '", driver.name, "': cannot start ", program, ": ", ErrnoText(error)));
  }
  // Debian 12's <sys/pidfd.h> lacks C linkage for C++; the system call is the same.
  child.pidfd = static_cast<int>(syscall(SYS_pidfd_open, child.pid, 0));
  return child;
}

enum class WaitEnd { kEnded, kTimedOut, kLost };

// Waits up to `seconds` for the child to end (its wait status in
// `wait_status`). kLost when it cannot be waited for: this process ignores
// SIGCHLD, or someone else reaped it.
WaitEnd WaitFor(const Child& child, double seconds, int* wait_status) {
  const Clock::time_point deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  while (true) {
    const pid_t done = waitpid(child.pid, wait_status, WNOHANG);
    if (done == child.pid) return WaitEnd::kEnded;
    if (done < 0 && errno != EINTR) return WaitEnd::kLost;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) return WaitEnd::kTimedOut;
    if (child.pidfd >= 0) {
      pollfd fd{child.pidfd, POLLIN, 0};
      poll(&fd, 1, static_cast<int>(std::min<long long>(left, 1000)));
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(std::min<long long>(left, 10)));
    }
  }
}

// Reaps the group's processes that are this process' children (the leader
// and orphans handed to this subreaper); true when no process of the group
// is left.
bool ReapGroup(pid_t group) {
  int status = 0;
  while (waitpid(-group, &status, WNOHANG) > 0) {
  }
  return kill(-group, 0) != 0 && errno == ESRCH;
}

// SIGKILL to the group until none of it is left (bounded: a process stuck
// in the kernel cannot be waited for forever).
void KillGroup(pid_t group) {
  const Clock::time_point give_up = Clock::now() + std::chrono::seconds(5);
  while (!ReapGroup(group) && Clock::now() < give_up) {
    kill(-group, SIGKILL);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

// SIGTERM to the group, a grace period for it to end, then SIGKILL.
void TerminateGroup(pid_t group, double grace_s) {
  kill(-group, SIGTERM);
  const Clock::time_point deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(grace_s));
  while (!ReapGroup(group) && Clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  KillGroup(group);
}

std::string WithStderr(std::string reason, const fs::path& folder, int lines) {
  const std::string tail = TailLines(folder / kStderrFile, lines);
  if (tail.empty()) return absl::StrCat(reason, "; its stderr is empty");
  return absl::StrCat(reason, "; last lines of its stderr:\n", tail);
}

std::string CodesText(const std::vector<int>& codes) { return absl::StrJoin(codes, ", "); }

// Runs the driver in `folder` (already filled) and reads its results.
absl::StatusOr<ExternalOutcome> RunInFolder(const DriverDeclaration& driver, const fs::path& folder,
                                            const RunOptions& options) {
  ExternalOutcome outcome;
  outcome.run_folder = folder;
  // Orphans of the driver become our children, so that the group can be
  // reaped to the last process (a zombie still counts as a group member).
  prctl(PR_SET_CHILD_SUBREAPER, 1);
  const Clock::time_point start = Clock::now();
  // Forked before the driver: if this process is killed outright, the
  // guard ends the group (group_guard.h).
  MBOPT_ASSIGN_OR_RETURN(GroupGuard guard, GroupGuard::Start());
  MBOPT_ASSIGN_OR_RETURN(const Child child, Spawn(driver, folder));
  guard.Watch(child.pid);
  int wait_status = 0;
  const WaitEnd end = WaitFor(child, driver.timeout_s, &wait_status);
  if (end == WaitEnd::kTimedOut) {
    TerminateGroup(child.pid, options.kill_grace_s);
  } else {
    // The driver is done; whatever it left running in its group is not.
    KillGroup(child.pid);
  }
  guard.Release();
  if (child.pidfd >= 0) close(child.pidfd);
  outcome.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (end == WaitEnd::kLost) {
    return absl::InternalError(absl::StrCat("driver '", driver.name, "': its process ", child.pid,
                                            " could not be waited for (is SIGCHLD ignored?)"));
  }
  const bool ended = end == WaitEnd::kEnded;

  const std::string who = absl::StrCat("driver '", driver.name, "'");
  if (!ended) {
    outcome.failure = spec::AnalysisFailure::Of(
        spec::FailureKind::kTimeLimit,
        WithStderr(absl::StrCat(who, " ran past its time limit of ", driver.timeout_s,
                                " s and was killed with its process group"),
                   folder, options.stderr_tail_lines));
    return outcome;
  }
  if (WIFSIGNALED(wait_status)) {
    outcome.term_signal = WTERMSIG(wait_status);
    outcome.failure = spec::AnalysisFailure::Of(
        spec::FailureKind::kInvalidModel,
        WithStderr(absl::StrCat(who, " was killed by signal ", outcome.term_signal, " (",
                                strsignal(outcome.term_signal), ")"),
                   folder, options.stderr_tail_lines));
    return outcome;
  }
  outcome.exit_code = WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : -1;
  const auto& codes = driver.success_exit_codes;
  if (std::find(codes.begin(), codes.end(), outcome.exit_code) == codes.end()) {
    outcome.failure = spec::AnalysisFailure::Of(
        spec::FailureKind::kInvalidModel,
        WithStderr(absl::StrCat(who, " exited with code ", outcome.exit_code, " (success: ", CodesText(codes), ")"),
                   folder, options.stderr_tail_lines));
    return outcome;
  }
  const fs::path results_path = folder / driver.results_file;
  for (const fs::path& where : {folder / kStdoutFile, results_path}) {
    if (FileContains(where, driver.failure_marker)) {
      outcome.failure = spec::AnalysisFailure::Of(
          spec::FailureKind::kInvalidModel,
          WithStderr(absl::StrCat(who, " reported failure: \"", driver.failure_marker, "\" in ",
                                  where.filename().string()),
                     folder, options.stderr_tail_lines));
      return outcome;
    }
  }
  std::error_code ec;
  if (!fs::is_regular_file(results_path, ec)) {
    outcome.failure = spec::AnalysisFailure::Of(
        spec::FailureKind::kInvalidModel,
        WithStderr(absl::StrCat(who, " wrote no results file ", driver.results_file), folder,
                   options.stderr_tail_lines));
    return outcome;
  }
  std::ifstream in(results_path, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  absl::StatusOr<ExternalResults> results = ParseResults(driver.results_format, text, driver.results_file, driver.parameters);
  if (!results.ok()) {
    outcome.failure = spec::AnalysisFailure::Of(
        spec::FailureKind::kInvalidModel,
        absl::StrCat(who, ": malformed results: ", results.status().message()));
    return outcome;
  }
  const std::string non_finite = results->FirstNonFinite();
  if (!non_finite.empty()) {
    outcome.failure = spec::AnalysisFailure::Of(
        spec::FailureKind::kNonFiniteValue,
        absl::StrCat(who, ": ", non_finite, " in ", driver.results_file, " is not finite"));
    return outcome;
  }
  outcome.results = *std::move(results);
  return outcome;
}

}  // namespace

absl::StatusOr<ExternalOutcome> RunExternalAnalysis(const DriverDeclaration& driver,
                                                    const std::map<std::string, double>& values,
                                                    const RunOptions& options) {
  if (!IsSafeName(options.analysis_id)) {
    return absl::InvalidArgumentError(absl::StrCat("analysis id \"", options.analysis_id,
                                                   "\": expected letters, digits, '_', '-', '.'"));
  }
  if (!IsSafeName(driver.name) || driver.command.empty() || !(driver.timeout_s > 0.0)) {
    return absl::InvalidArgumentError(absl::StrCat("driver '", driver.name, "' is not a valid declaration"));
  }
  MBOPT_RETURN_IF_ERROR(CheckValues(driver, values));
  std::string input;
  if (!driver.input_file.empty()) {
    MBOPT_ASSIGN_OR_RETURN(input, FillTemplate(driver.input_template_text, driver.input_template_source, values));
  }

  std::error_code ec;
  fs::create_directories(options.work_directory, ec);
  if (ec) {
    return absl::FailedPreconditionError(
        absl::StrCat("cannot create work directory ", options.work_directory.string(), ": ", ec.message()));
  }
  const fs::path folder = options.work_directory / absl::StrCat(options.analysis_id, "-", driver.name);
  if (mkdir(folder.c_str(), 0700) != 0) {
    return absl::FailedPreconditionError(
        absl::StrCat("cannot create analysis folder ", folder.string(), ": ", ErrnoText(errno)));
  }
  // mkdir's mode passes through the umask; the folder is the worker's alone.
  chmod(folder.c_str(), 0700);

  absl::StatusOr<ExternalOutcome> outcome = [&]() -> absl::StatusOr<ExternalOutcome> {
    for (const std::string& file : driver.files) {
      MBOPT_RETURN_IF_ERROR(CopyInside(driver.base_directory / file, folder / file, driver.base_directory, file));
    }
    if (!driver.input_file.empty()) MBOPT_RETURN_IF_ERROR(WriteFile(folder / driver.input_file, input));
    return RunInFolder(driver, folder, options);
  }();

  if (!options.keep_run_folder) {
    fs::remove_all(folder, ec);
    if (ec && outcome.ok()) outcome->cleanup_problem = absl::StrCat("cannot remove ", folder.string(), ": ", ec.message());
  }
  return outcome;
}

}  // namespace mbopt::external
