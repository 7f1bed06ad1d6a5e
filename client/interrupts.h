// Ctrl-C (SIGINT), SIGTERM and SIGHUP for the long-running commands (watch, run).
// Install() blocks these signals in every thread and starts one thread that
// waits for them with sigwait; on a signal it records the interruption and
// cancels the gRPC call registered with SetCancelTarget, so the command
// returns from a blocking stream read and cleans up. Call Install() before
// any other thread is started so that every thread inherits the mask.
#pragma once

#include <grpcpp/grpcpp.h>

namespace mbopt::client {

class Interrupts {
 public:
  static void Install();
  static bool interrupted();
  // The call to cancel on a signal (nullptr: none). If a signal already
  // arrived, the context is cancelled at once.
  static void SetCancelTarget(grpc::ClientContext* context);
};

}  // namespace mbopt::client
