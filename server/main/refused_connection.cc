#include "server/main/refused_connection.h"

namespace mbopt::server_main {

namespace {

constexpr std::string_view kHandshakeFailed = "Handshake failed with fatal error ";

struct Cause {
  std::string_view openssl_reason;  // the end of OpenSSL's error string
  std::string_view meaning;
};

// OpenSSL 3's reason strings for what clients most often get wrong.
constexpr Cause kCauses[] = {
    {"wrong version number", "the client does not speak TLS (a client without --tls-ca, or not a gRPC client)"},
    {"http request", "the client sent a plain HTTP request, not TLS"},
    {"packet length too long", "the client does not speak TLS"},
    {"tlsv1 alert unknown ca",
     "the client does not trust this server's certificate (its --tls-ca is not the CA that signed server.pem)"},
    {"sslv3 alert bad certificate", "the client found this server's certificate unacceptable (a wrong host name?)"},
    {"sslv3 alert certificate expired", "the client found this server's certificate expired (mbopt-server renew-cert)"},
    {"peer did not return a certificate", "the client sent no certificate, and this server asks for one (--worker-ca)"},
    {"certificate verify failed", "the client's certificate is not signed by the CA this server trusts (--worker-ca)"},
    {"no shared cipher", "the client and this server have no TLS cipher in common"},
    {"unsupported protocol", "the client offers no TLS version this server accepts (TLS 1.2 or later)"},
    {"no protocols available", "the client offers no TLS version this server accepts (TLS 1.2 or later)"},
};

}  // namespace

std::optional<std::string> RefusedConnectionLine(std::string_view grpc_message) {
  const size_t at = grpc_message.find(kHandshakeFailed);
  if (at == std::string_view::npos) return std::nullopt;
  std::string_view detail = grpc_message.substr(at + kHandshakeFailed.size());
  while (!detail.empty() && (detail.back() == '.' || detail.back() == '\n' || detail.back() == ' ')) {
    detail.remove_suffix(1);
  }
  std::string line = "refused a connection: ";
  if (detail.rfind("SSL_ERROR_SYSCALL", 0) == 0 || detail.rfind("SSL_ERROR_ZERO_RETURN", 0) == 0) {
    return line + "the client closed it during the TLS handshake";
  }
  for (const Cause& cause : kCauses) {
    if (detail.size() >= cause.openssl_reason.size() &&
        detail.substr(detail.size() - cause.openssl_reason.size()) == cause.openssl_reason) {
      return line.append(cause.meaning);
    }
  }
  // Another failure: OpenSSL's reason, the text after its last "::".
  const size_t reason = detail.rfind("::");
  return line.append("TLS handshake failed: ").append(reason == std::string_view::npos ? detail : detail.substr(reason + 2));
}

}  // namespace mbopt::server_main
