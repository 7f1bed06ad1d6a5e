// Whether an address the server is asked to listen on is reachable only
// from this machine. The server listens off loopback only when told it may
// do so without TLS and tokens (`--insecure`): until it has them, that is
// the only way (docs/server.md, "Security").
#pragma once

#include <string>

namespace mbopt::service {

// true for 127.0.0.0/8, ::1, "localhost" and Unix domain sockets; false for
// everything else, including an empty host (":50051", all interfaces),
// 0.0.0.0, [::] and any name or address of another interface.
bool IsLoopbackAddress(const std::string& listen_address);

// The address clients dial for a server listening on `listen_address` that
// got `port` (the port asked for, or the one chosen for port 0): the host
// with that port, or a Unix domain socket's address unchanged.
std::string DialAddress(const std::string& listen_address, int port);

}  // namespace mbopt::service
