// Why a connection to a server failed, in words. gRPC reports a failed TLS
// handshake only as "failed to connect to all addresses"; this makes the
// same connection itself with OpenSSL and names the cause: the server's
// certificate is not signed by the CA given, has expired, is made for other
// host names, the server wants a client certificate, the port does not
// speak TLS, or it does and the client connected without it.
#pragma once

#include <string>

#include "common/secure_channel/client_security.h"

namespace mbopt::secure_channel {

// One sentence naming the cause, or "" when this finds none (for example
// when nothing listens at the address: gRPC's own message says that).
// Makes one TCP connection, with a few seconds' timeout.
std::string DiagnoseConnectionFailure(const std::string& address, const ClientSecurity& security);

}  // namespace mbopt::secure_channel
