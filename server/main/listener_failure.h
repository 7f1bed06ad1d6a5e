// gRPC 1.51 (Debian 12) stops accepting connections for good when accept4
// fails with anything but EAGAIN or ECONNABORTED: when the process runs out
// of descriptors (EMFILE) its listener is abandoned, and the server, still
// alive, answers nothing new even after the descriptors are free again. The
// only sign is gRPC's log line "Failed accept4: ...". This watches gRPC's
// log for it, so that the server can stop (and its service manager start it
// again: systemd's Restart=on-failure, a Kubernetes pod's restart) instead
// of staying up deaf. Newer gRPC retries accept4 after a delay; this watch
// then never fires.
#pragma once

#include <string>

namespace mbopt::server_main {

// Routes gRPC's log lines through a function that passes them on to
// stderr ("mbopt-server: grpc: ..."; a refused TLS connection as one
// readable line unless GRPC_VERBOSITY is set, refused_connection.h) and, on
// a failed accept4, records the
// message and sends SIGTERM to this process (whose main thread waits for
// it). Call once, before the server starts.
void WatchForListenerFailure();

// The failed accept4's message ("Failed accept4: Too many open files"),
// or "" while none happened.
std::string ListenerFailure();

}  // namespace mbopt::server_main
