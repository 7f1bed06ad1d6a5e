#include "server/main/refused_connection.h"

#include <optional>
#include <string>

#include <gtest/gtest.h>

namespace mbopt::server_main {
namespace {

// The messages are gRPC 1.51's (ssl_transport_security.cc) with OpenSSL 3's
// error strings, as the server's log showed them.
TEST(RefusedConnection, KnownHandshakeFailuresSayWhatTheClientDidWrong) {
  EXPECT_EQ(RefusedConnectionLine("Handshake failed with fatal error SSL_ERROR_SSL: error:0A00010B:SSL "
                                  "routines::wrong version number."),
            "refused a connection: the client does not speak TLS (a client without --tls-ca, or not a gRPC "
            "client)");
  EXPECT_EQ(RefusedConnectionLine("Handshake failed with fatal error SSL_ERROR_SSL: error:0A000418:SSL "
                                  "routines::tlsv1 alert unknown ca."),
            "refused a connection: the client does not trust this server's certificate (its --tls-ca is not the "
            "CA that signed server.pem)");
  EXPECT_EQ(RefusedConnectionLine("Handshake failed with fatal error SSL_ERROR_SSL: error:0A0000C7:SSL "
                                  "routines::peer did not return a certificate."),
            "refused a connection: the client sent no certificate, and this server asks for one (--worker-ca)");
  EXPECT_EQ(RefusedConnectionLine("Handshake failed with fatal error SSL_ERROR_SYSCALL: errno 0"),
            "refused a connection: the client closed it during the TLS handshake");
}

TEST(RefusedConnection, AnotherHandshakeFailureKeepsOpenSslsReasonAndOtherLinesPass) {
  EXPECT_EQ(RefusedConnectionLine("Handshake failed with fatal error SSL_ERROR_SSL: error:0A000086:SSL "
                                  "routines::bad key share."),
            "refused a connection: TLS handshake failed: bad key share");
  EXPECT_EQ(RefusedConnectionLine("Failed accept4: Too many open files"), std::nullopt);
  EXPECT_EQ(RefusedConnectionLine(""), std::nullopt);
}

}  // namespace
}  // namespace mbopt::server_main
