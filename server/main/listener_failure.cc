#include "server/main/listener_failure.h"

#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <mutex>

#include <grpc/support/log.h>

namespace mbopt::server_main {
namespace {

constexpr const char kAcceptFailed[] = "Failed accept4";

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

void WatchForListenerFailure() { gpr_set_log_function(&OnGrpcLog); }

std::string ListenerFailure() {
  std::lock_guard<std::mutex> lock(failure_mutex);
  return failure;
}

}  // namespace mbopt::server_main
