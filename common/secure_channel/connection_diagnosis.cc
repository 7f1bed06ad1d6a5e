#include "common/secure_channel/connection_diagnosis.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/ssl.h>
#include <openssl/x509v3.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <memory>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/x509/x509_text.h"

namespace mbopt::secure_channel {
namespace {

constexpr int kTimeoutMs = 3000;

using x509::Owned;

// The TLS objects of one connection attempt.
using SslContext = std::unique_ptr<SSL_CTX, decltype(&SSL_CTX_free)>;
using Ssl = std::unique_ptr<SSL, decltype(&SSL_free)>;

class Socket {
 public:
  explicit Socket(int fd) : fd_(fd) {}
  ~Socket() {
    if (fd_ >= 0) ::close(fd_);
  }
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;
  int fd() const { return fd_; }

 private:
  int fd_;
};

// "host:port", "[v6]:port", "dns:host:port" or "ipv4:a.b.c.d:port" into
// host and port; false for what this cannot dial (unix sockets).
bool SplitAddress(std::string address, std::string* host, std::string* port) {
  for (const char* scheme : {"dns:///", "dns:", "ipv4:", "ipv6:"}) {
    if (address.rfind(scheme, 0) == 0) address = address.substr(std::string(scheme).size());
  }
  if (address.rfind("unix", 0) == 0) return false;
  if (!address.empty() && address.front() == '[') {
    const std::size_t close = address.find(']');
    if (close == std::string::npos || close + 2 > address.size() || address[close + 1] != ':') return false;
    *host = address.substr(1, close - 1);
    *port = address.substr(close + 2);
    return true;
  }
  const std::size_t colon = address.rfind(':');
  if (colon == std::string::npos) return false;
  *host = address.substr(0, colon);
  *port = address.substr(colon + 1);
  return !host->empty() && !port->empty();
}

// A connected TCP socket, or -1.
int Dial(const std::string& host, const std::string& port) {
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (::getaddrinfo(host.c_str(), port.c_str(), &hints, &found) != 0) return -1;
  int result = -1;
  for (addrinfo* a = found; a != nullptr && result < 0; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    timeval timeout{kTimeoutMs / 1000, 0};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
    ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof timeout);
    if (::connect(fd, a->ai_addr, a->ai_addrlen) == 0) {
      result = fd;
    } else {
      ::close(fd);
    }
  }
  ::freeaddrinfo(found);
  return result;
}

bool IsIpAddress(const std::string& host) {
  in_addr v4{};
  in6_addr v6{};
  return inet_pton(AF_INET, host.c_str(), &v4) == 1 || inet_pton(AF_INET6, host.c_str(), &v6) == 1;
}

bool AddCaCertificates(SSL_CTX* context, const std::string& pem) {
  Owned<BIO> bio(BIO_new_mem_buf(pem.data(), static_cast<int>(pem.size())));
  X509_STORE* store = SSL_CTX_get_cert_store(context);
  int added = 0;
  while (X509* certificate = PEM_read_bio_X509(bio.get(), nullptr, nullptr, nullptr)) {
    if (X509_STORE_add_cert(store, certificate) == 1) ++added;
    X509_free(certificate);
  }
  ERR_clear_error();
  return added > 0;
}

std::string CertificateHosts(const X509* certificate) {
  const std::vector<std::string> hosts = x509::CertificateHosts(certificate);
  return hosts.empty() ? "no host names" : absl::StrJoin(hosts, ", ");
}

// What the peer said about the handshake when it refused it.
std::string HandshakeError() {
  const unsigned long code = ERR_peek_last_error();
  ERR_clear_error();
  if (code == 0) return "";
  const char* reason = ERR_reason_error_string(code);
  return reason != nullptr ? reason : "";
}

}  // namespace

std::string DiagnoseConnectionFailure(const std::string& address, const ClientSecurity& security) {
  std::string host, port;
  if (!SplitAddress(address, &host, &port)) return "";
  Socket socket(Dial(host, port));
  if (socket.fd() < 0) return "";  // nothing listens there: gRPC's message says so

  SslContext context(SSL_CTX_new(TLS_client_method()), &SSL_CTX_free);
  if (context == nullptr) return "";
  SSL_CTX_set_verify(context.get(), SSL_VERIFY_NONE, nullptr);  // judged below, with the reason
  if (security.tls && !AddCaCertificates(context.get(), security.ca_pem)) {
    return absl::StrCat(security.ca_file, " holds no PEM certificate (--tls-ca names the CA certificate, ca.pem)");
  }
  if (!security.cert_pem.empty()) {
    Owned<X509> certificate = x509::ReadCertificate(security.cert_pem);
    Owned<EVP_PKEY> key = x509::ReadPrivateKey(security.key_pem);
    if (certificate == nullptr || key == nullptr || SSL_CTX_use_certificate(context.get(), certificate.get()) != 1 ||
        SSL_CTX_use_PrivateKey(context.get(), key.get()) != 1) {
      ERR_clear_error();
      return "the client certificate (--tls-cert) or its key (--tls-key) cannot be read as PEM, or they do not match";
    }
  }
  Ssl ssl(SSL_new(context.get()), &SSL_free);
  SSL_set_fd(ssl.get(), socket.fd());
  static const unsigned char kAlpn[] = {2, 'h', '2'};
  SSL_set_alpn_protos(ssl.get(), kAlpn, sizeof kAlpn);
  const std::string name = security.server_name.empty() ? host : security.server_name;
  if (IsIpAddress(name)) {
    X509_VERIFY_PARAM_set1_ip_asc(SSL_get0_param(ssl.get()), name.c_str());
  } else {
    SSL_set1_host(ssl.get(), name.c_str());
    SSL_set_tlsext_host_name(ssl.get(), name.c_str());
  }
  ERR_clear_error();
  if (SSL_connect(ssl.get()) != 1) {
    const std::string reason = HandshakeError();
    if (reason.find("wrong version number") != std::string::npos ||
        reason.find("packet length too long") != std::string::npos || reason.find("record layer") != std::string::npos ||
        reason.find("http request") != std::string::npos) {
      return security.tls ? absl::StrCat("the server at ", address,
                                         " does not speak TLS (started without --tls-dir); leave out --tls-ca "
                                         "and MBOPT_TLS_CA for it")
                          : "";
    }
    if (!security.tls) return "";
    if (reason.find("certificate required") != std::string::npos ||
        reason.find("handshake failure") != std::string::npos) {
      return absl::StrCat("the server at ", address,
                          " wants a client certificate signed by its worker CA (--tls-cert and --tls-key): ",
                          reason.empty() ? "handshake refused" : reason);
    }
    if (reason.find("unknown ca") != std::string::npos || reason.find("bad certificate") != std::string::npos ||
        reason.find("certificate expired") != std::string::npos) {
      return absl::StrCat("the server at ", address, " refused the client certificate (--tls-cert): ", reason);
    }
    return reason.empty() ? "" : absl::StrCat("TLS handshake with ", address, " failed: ", reason);
  }
  if (!security.tls) {
    return absl::StrCat("the server at ", address,
                        " speaks TLS: give its CA certificate with --tls-ca FILE (or MBOPT_TLS_CA), and a token "
                        "with --token-file FILE (or MBOPT_TOKEN_FILE)");
  }
  X509* peer = SSL_get0_peer_certificate(ssl.get());
  const long verdict = SSL_get_verify_result(ssl.get());
  if (peer == nullptr || verdict == X509_V_OK) return "";
  const std::string what = absl::StrCat("the server's certificate (for ", CertificateHosts(peer), ")");
  switch (verdict) {
    case X509_V_ERR_CERT_HAS_EXPIRED:
      return absl::StrCat(what, " expired on ", x509::TimeText(X509_get0_notAfter(peer)),
                          "; make a new one (deploy/README.md, \"Security\")");
    case X509_V_ERR_CERT_NOT_YET_VALID:
      return absl::StrCat(what, " is not valid before ", x509::TimeText(X509_get0_notBefore(peer)),
                          ": is this machine's clock right?");
    case X509_V_ERR_HOSTNAME_MISMATCH:
    case X509_V_ERR_IP_ADDRESS_MISMATCH:
      return absl::StrCat(what, " is not made for '", name,
                          "': connect to one of its names, or pass --tls-server-name with one of them");
    case X509_V_ERR_UNABLE_TO_GET_ISSUER_CERT_LOCALLY:
    case X509_V_ERR_UNABLE_TO_GET_ISSUER_CERT:
    case X509_V_ERR_SELF_SIGNED_CERT_IN_CHAIN:
    case X509_V_ERR_DEPTH_ZERO_SELF_SIGNED_CERT:
    case X509_V_ERR_CERT_SIGNATURE_FAILURE:
      return absl::StrCat(what, " is not signed by the CA in ", security.ca_file,
                          " (--tls-ca names the ca.pem that made the server's certificate)");
    default:
      return absl::StrCat(what, " is not trusted: ", X509_verify_cert_error_string(verdict));
  }
}

}  // namespace mbopt::secure_channel
