#include "server/main/listener_failure.h"

#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <optional>

#include <grpc/support/log.h>

#include "server/main/refused_connection.h"

namespace mbopt::server_main {
namespace {

constexpr const char kAcceptFailed[] = "Failed accept4";

// Whether gRPC's own lines were asked for (GRPC_VERBOSITY): then they are
// written as they come, refused connections included.
bool raw_grpc_lines = false;

std::mutex failure_mutex;
std::string failure;  // guarded by failure_mutex

const char* SeverityLetter(gpr_log_severity severity) {
  switch (severity) {
    case GPR_LOG_SEVERITY_DEBUG:
      return "D";
    case GPR_LOG_SEVERITY_INFO:
      return "I";
    case GPR_LOG_SEVERITY_ERROR:
      return "E";
  }
  return "?";
}

// Runs on gRPC's threads, some holding gRPC's locks: it only writes a line,
// takes its own lock and sends a signal.
void OnGrpcLog(gpr_log_func_args* args) {
  if (!raw_grpc_lines && args->message != nullptr) {
    if (const std::optional<std::string> line = RefusedConnectionLine(args->message)) {
      std::fprintf(stderr, "mbopt-server: %s\n", line->c_str());
      return;
    }
  }
  const char* file = args->file != nullptr ? std::strrchr(args->file, '/') : nullptr;
  std::fprintf(stderr, "mbopt-server: grpc %s %s:%d: %s\n", SeverityLetter(args->severity),
               file != nullptr ? file + 1 : (args->file != nullptr ? args->file : "?"), args->line,
               args->message != nullptr ? args->message : "");
  if (args->message == nullptr || std::strncmp(args->message, kAcceptFailed, sizeof kAcceptFailed - 1) != 0) return;
  {
    std::lock_guard<std::mutex> lock(failure_mutex);
    if (!failure.empty()) return;
    failure = args->message;
  }
  ::kill(::getpid(), SIGTERM);
}

}  // namespace

void WatchForListenerFailure() {
  const char* verbosity = std::getenv("GRPC_VERBOSITY");
  raw_grpc_lines = verbosity != nullptr && verbosity[0] != '\0';
  gpr_set_log_function(&OnGrpcLog);
}

std::string ListenerFailure() {
  std::lock_guard<std::mutex> lock(failure_mutex);
  return failure;
}

}  // namespace mbopt::server_main
