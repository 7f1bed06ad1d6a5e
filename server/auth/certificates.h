// X.509 certificates for the server's TLS, made and checked with OpenSSL:
// the certificate authority of one installation, the server's certificate
// for the host names clients use, and client certificates for workers
// (mutual TLS). Keys are ECDSA P-256, signatures SHA-256; everything is PEM.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace mbopt::auth {

struct KeyAndCertificate {
  std::string key_pem;          // PKCS#8, unencrypted: keep the file 0600
  std::string certificate_pem;
};

enum class CertificateKind { kAuthority, kServer, kClient };

struct CertificateRequest {
  CertificateKind kind = CertificateKind::kServer;
  std::string common_name;
  // A server's names: DNS names and IP addresses, as clients write them in
  // --server. Clients check the name they connected to against these.
  std::vector<std::string> hosts;
  // Validity, in seconds from now. Starts a little in the past so that a
  // machine whose clock is behind accepts a certificate made just now.
  std::int64_t not_before_s = -3600;
  std::int64_t not_after_s = std::int64_t{825} * 86400;
};

// A new key and its certificate, signed by `issuer` (nullptr: self-signed,
// for an authority).
absl::StatusOr<KeyAndCertificate> MakeCertificate(const CertificateRequest& request,
                                                  const KeyAndCertificate* issuer);

struct CertificateInfo {
  std::string subject;    // e.g. "CN=mbopt server"
  std::string not_after;  // e.g. "Mar  1 12:00:00 2029 GMT"
  bool expired = false;
  bool not_yet_valid = false;
  std::int64_t seconds_left = 0;  // until not_after; negative once expired
  std::vector<std::string> hosts;  // its DNS and IP subject alternative names
};

// InvalidArgument naming `source_name` when `pem` holds no certificate.
absl::StatusOr<CertificateInfo> InspectCertificate(const std::string& pem, const std::string& source_name);

// InvalidArgument naming both files when the key is not the certificate's
// (or either cannot be read as PEM).
absl::Status CheckKeyMatchesCertificate(const std::string& certificate_pem, const std::string& key_pem,
                                        const std::string& certificate_name, const std::string& key_name);

}  // namespace mbopt::auth
