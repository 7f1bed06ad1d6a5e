// gRPC reports a refused TLS connection with OpenSSL's words
// ("grpc E ssl_transport_security.cc:1501: Handshake failed with fatal error
// SSL_ERROR_SSL: error:0A00010B:SSL routines::wrong version number."); the
// server's log says instead what happened and what the client should do,
// in one line. gRPC 1.51 gives no peer address at that point, so the line
// cannot name the client; its own lines come back with GRPC_VERBOSITY set.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace mbopt::server_main {

// The readable line ("refused a connection: ...") for a gRPC log message
// that reports a failed TLS handshake, or none for any other message.
std::optional<std::string> RefusedConnectionLine(std::string_view grpc_message);

}  // namespace mbopt::server_main
