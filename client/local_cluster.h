// The embedded default of `mbopt run`: an mbopt-server on 127.0.0.1 (port
// chosen by the OS) and N local mbopt-worker processes, started and stopped
// as one. Readiness comes from the server's "mbopt-server listening on
// HOST:PORT" line on its stdout, never from sleeping. Children write their
// logs to files in `log_dir`.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/statusor.h"
#include "client/subprocess.h"

namespace mbopt::client {

// The path of a program shipped with mbopt: $<env_var> if set, else
// <dir of this executable>/<name>, else the build tree's
// <dir of this executable>/../<build_subdir>/<name>. NotFound if none exists.
absl::StatusOr<std::string> FindMboptBinary(const std::string& name, const char* env_var,
                                            const std::string& build_subdir);

// Parses the server's readiness line; InvalidArgument if it is not one.
absl::StatusOr<std::string> ParseListeningLine(const std::string& line);

struct LocalClusterOptions {
  std::string server_binary;
  std::string worker_binary;
  std::string db_path;
  std::string log_dir;  // server.log, worker-<i>.log, port
  int workers = 1;
  // The server only shows the database's jobs (mbopt-server --inspect).
  bool inspect_only = false;
  // Added to every worker's command line (e.g. --drivers FILE).
  std::vector<std::string> worker_args;
  std::chrono::milliseconds ready_timeout{60000};  // failure guard only
};

class LocalCluster {
 public:
  // Also clears this process's MBOPT_TLS_* and MBOPT_TOKEN* variables
  // (common/secure_channel): the private server has neither TLS nor tokens.
  static absl::StatusOr<std::unique_ptr<LocalCluster>> Start(const LocalClusterOptions& options);
  ~LocalCluster();

  const std::string& address() const { return address_; }
  // Stops workers, then the server: SIGTERM, then waits (SIGKILL after a
  // grace period). Safe to call twice.
  void Stop();
  // The server's log so far (for error messages).
  std::string ServerLogTail() const;

 private:
  LocalCluster() = default;

  LocalClusterOptions options_;
  std::string address_;
  std::unique_ptr<Subprocess> server_;
  std::vector<Subprocess> workers_;
  std::thread drain_;  // reads the server's stdout after the ready line
};

}  // namespace mbopt::client
