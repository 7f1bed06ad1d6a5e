#include "server/auth/certificates.h"

#include <arpa/inet.h>
#include <openssl/bio.h>
#include <openssl/bn.h>
#include <openssl/ec.h>
#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/x509.h>
#include <openssl/x509v3.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/x509/x509_text.h"

namespace mbopt::auth {
namespace {

using x509::BioText;
using x509::Owned;
using x509::ReadCertificate;

// The last OpenSSL error as text, and the queue cleared.
std::string OpenSslError() {
  const unsigned long code = ERR_get_error();
  ERR_clear_error();
  if (code == 0) return "unknown OpenSSL error";
  char text[256];
  ERR_error_string_n(code, text, sizeof text);
  return text;
}

absl::Status Failed(const std::string& what) {
  return absl::InternalError(absl::StrCat(what, ": ", OpenSslError()));
}

absl::Status AddExtension(X509* certificate, X509* issuer, int nid, const std::string& value) {
  X509V3_CTX context;
  X509V3_set_ctx(&context, issuer, certificate, nullptr, nullptr, 0);
  Owned<X509_EXTENSION> extension(X509V3_EXT_conf_nid(nullptr, &context, nid, value.c_str()));
  if (extension == nullptr || X509_add_ext(certificate, extension.get(), -1) != 1) {
    return Failed(absl::StrCat("certificate extension ", OBJ_nid2sn(nid), " = ", value));
  }
  return absl::OkStatus();
}

// "DNS:name" or "IP:address" for each host.
std::string AltNames(const std::vector<std::string>& hosts) {
  std::vector<std::string> names;
  for (const std::string& host : hosts) {
    in_addr v4{};
    in6_addr v6{};
    const bool ip = inet_pton(AF_INET, host.c_str(), &v4) == 1 || inet_pton(AF_INET6, host.c_str(), &v6) == 1;
    names.push_back(absl::StrCat(ip ? "IP:" : "DNS:", host));
  }
  return absl::StrJoin(names, ",");
}

}  // namespace

absl::StatusOr<KeyAndCertificate> MakeCertificate(const CertificateRequest& request,
                                                  const KeyAndCertificate* issuer) {
  if (request.kind != CertificateKind::kAuthority && issuer == nullptr) {
    return absl::InvalidArgumentError("only an authority's certificate is self-signed");
  }
  if (request.kind == CertificateKind::kServer && request.hosts.empty()) {
    return absl::InvalidArgumentError("a server certificate needs at least one host name or address");
  }
  Owned<EVP_PKEY> key(EVP_EC_gen("P-256"));
  if (key == nullptr) return Failed("making an EC P-256 key");
  Owned<X509> issuer_certificate;
  Owned<EVP_PKEY> issuer_key;
  if (issuer != nullptr) {
    issuer_certificate = ReadCertificate(issuer->certificate_pem);
    issuer_key = x509::ReadPrivateKey(issuer->key_pem);
    if (issuer_certificate == nullptr || issuer_key == nullptr) {
      return absl::InvalidArgumentError("the issuer's certificate or key is not PEM");
    }
  }
  Owned<X509> certificate(X509_new());
  X509_set_version(certificate.get(), 2);  // X.509 v3
  Owned<BIGNUM> serial(BN_new());
  if (BN_rand(serial.get(), 127, BN_RAND_TOP_ANY, BN_RAND_BOTTOM_ANY) != 1 ||
      BN_to_ASN1_INTEGER(serial.get(), X509_get_serialNumber(certificate.get())) == nullptr) {
    return Failed("a random serial number");
  }
  X509_gmtime_adj(X509_getm_notBefore(certificate.get()), request.not_before_s);
  X509_gmtime_adj(X509_getm_notAfter(certificate.get()), request.not_after_s);
  X509_set_pubkey(certificate.get(), key.get());
  X509_NAME* subject = X509_get_subject_name(certificate.get());
  X509_NAME_add_entry_by_txt(subject, "CN", MBSTRING_UTF8,
                             reinterpret_cast<const unsigned char*>(request.common_name.c_str()), -1, -1, 0);
  X509_set_issuer_name(certificate.get(),
                       issuer != nullptr ? X509_get_subject_name(issuer_certificate.get()) : subject);
  X509* signer = issuer != nullptr ? issuer_certificate.get() : certificate.get();
  switch (request.kind) {
    case CertificateKind::kAuthority:
      if (auto s = AddExtension(certificate.get(), signer, NID_basic_constraints, "critical,CA:TRUE,pathlen:0");
          !s.ok())
        return s;
      if (auto s = AddExtension(certificate.get(), signer, NID_key_usage, "critical,keyCertSign,cRLSign"); !s.ok())
        return s;
      break;
    case CertificateKind::kServer:
    case CertificateKind::kClient: {
      const bool server = request.kind == CertificateKind::kServer;
      if (auto s = AddExtension(certificate.get(), signer, NID_basic_constraints, "critical,CA:FALSE"); !s.ok())
        return s;
      if (auto s = AddExtension(certificate.get(), signer, NID_key_usage, "critical,digitalSignature"); !s.ok())
        return s;
      if (auto s = AddExtension(certificate.get(), signer, NID_ext_key_usage, server ? "serverAuth" : "clientAuth");
          !s.ok())
        return s;
      if (!request.hosts.empty()) {
        if (auto s = AddExtension(certificate.get(), signer, NID_subject_alt_name, AltNames(request.hosts)); !s.ok())
          return s;
      }
      break;
    }
  }
  if (auto s = AddExtension(certificate.get(), signer, NID_subject_key_identifier, "hash"); !s.ok()) return s;
  if (issuer != nullptr) {
    if (auto s = AddExtension(certificate.get(), signer, NID_authority_key_identifier, "keyid:always"); !s.ok())
      return s;
  }
  EVP_PKEY* signing_key = issuer != nullptr ? issuer_key.get() : key.get();
  if (X509_sign(certificate.get(), signing_key, EVP_sha256()) == 0) return Failed("signing the certificate");

  KeyAndCertificate out;
  Owned<BIO> key_bio(BIO_new(BIO_s_mem()));
  if (PEM_write_bio_PrivateKey(key_bio.get(), key.get(), nullptr, nullptr, 0, nullptr, nullptr) != 1) {
    return Failed("writing the key as PEM");
  }
  out.key_pem = BioText(key_bio.get());
  Owned<BIO> certificate_bio(BIO_new(BIO_s_mem()));
  if (PEM_write_bio_X509(certificate_bio.get(), certificate.get()) != 1) return Failed("writing the certificate");
  out.certificate_pem = BioText(certificate_bio.get());
  return out;
}

absl::StatusOr<CertificateInfo> InspectCertificate(const std::string& pem, const std::string& source_name) {
  Owned<X509> certificate = ReadCertificate(pem);
  if (certificate == nullptr) {
    ERR_clear_error();
    return absl::InvalidArgumentError(
        absl::StrCat(source_name, ": no PEM certificate (a file starting -----BEGIN CERTIFICATE-----)"));
  }
  CertificateInfo info;
  char subject[512];
  X509_NAME_oneline(X509_get_subject_name(certificate.get()), subject, sizeof subject);
  info.subject = subject;
  info.not_after = x509::TimeText(X509_get0_notAfter(certificate.get()));
  info.expired = X509_cmp_current_time(X509_get0_notAfter(certificate.get())) < 0;
  info.not_yet_valid = X509_cmp_current_time(X509_get0_notBefore(certificate.get())) > 0;
  int days = 0, seconds = 0;
  if (ASN1_TIME_diff(&days, &seconds, nullptr, X509_get0_notAfter(certificate.get())) == 1) {
    info.seconds_left = std::int64_t{days} * 86400 + seconds;
  }
  info.hosts = x509::CertificateHosts(certificate.get());
  return info;
}

absl::Status CheckKeyMatchesCertificate(const std::string& certificate_pem, const std::string& key_pem,
                                        const std::string& certificate_name, const std::string& key_name) {
  Owned<X509> certificate = ReadCertificate(certificate_pem);
  if (certificate == nullptr) {
    ERR_clear_error();
    return absl::InvalidArgumentError(absl::StrCat(certificate_name, ": no PEM certificate"));
  }
  Owned<EVP_PKEY> key = x509::ReadPrivateKey(key_pem);
  if (key == nullptr) {
    ERR_clear_error();
    return absl::InvalidArgumentError(absl::StrCat(key_name, ": no PEM private key"));
  }
  if (X509_check_private_key(certificate.get(), key.get()) != 1) {
    ERR_clear_error();
    return absl::InvalidArgumentError(
        absl::StrCat(key_name, " is not the private key of the certificate ", certificate_name));
  }
  return absl::OkStatus();
}

}  // namespace mbopt::auth
