// OpenSSL's X.509 objects as mbopt reads and shows them: owned pointers,
// PEM in, the host names a certificate carries and its dates as text.
// Shared by the server's certificate making and checks (server/auth) and
// the clients' naming of a failed connection (common/secure_channel).
#pragma once

#include <openssl/bio.h>
#include <openssl/bn.h>
#include <openssl/evp.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include <memory>
#include <string>
#include <vector>

namespace mbopt::x509 {

struct Free {
  void operator()(EVP_PKEY* p) const { EVP_PKEY_free(p); }
  void operator()(X509* p) const { X509_free(p); }
  void operator()(BIO* p) const { BIO_free(p); }
  void operator()(BIGNUM* p) const { BN_free(p); }
  void operator()(X509_EXTENSION* p) const { X509_EXTENSION_free(p); }
  void operator()(GENERAL_NAMES* p) const { GENERAL_NAMES_free(p); }
};
template <typename T>
using Owned = std::unique_ptr<T, Free>;

// The first certificate, or the private key, of `pem`; null when there is
// none (OpenSSL's error queue is left as it is).
Owned<X509> ReadCertificate(const std::string& pem);
Owned<EVP_PKEY> ReadPrivateKey(const std::string& pem);

// The DNS names and IP addresses of the certificate's subject alternative
// names, in order.
std::vector<std::string> CertificateHosts(const X509* certificate);

// e.g. "Mar  1 12:00:00 2029 GMT".
std::string TimeText(const ASN1_TIME* time);

// What a memory BIO holds.
std::string BioText(BIO* bio);

}  // namespace mbopt::x509
