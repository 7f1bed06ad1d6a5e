// Certificates made by init-tls, checked with OpenSSL's own verification:
// the chain, the names, the validity and the key pairing.
#include "server/auth/certificates.h"

#include <openssl/pem.h>
#include <openssl/x509.h>
#include <openssl/x509_vfy.h>
#include <openssl/x509v3.h>

#include <memory>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace mbopt::auth {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

std::unique_ptr<X509, decltype(&X509_free)> Parse(const std::string& pem) {
  BIO* bio = BIO_new_mem_buf(pem.data(), static_cast<int>(pem.size()));
  X509* certificate = PEM_read_bio_X509(bio, nullptr, nullptr, nullptr);
  BIO_free(bio);
  return {certificate, &X509_free};
}

// OpenSSL's verdict on `leaf` against the authority `ca`, for `purpose`.
int Verify(const std::string& ca, const std::string& leaf, int purpose) {
  auto root = Parse(ca);
  auto certificate = Parse(leaf);
  X509_STORE* store = X509_STORE_new();
  X509_STORE_add_cert(store, root.get());
  X509_STORE_CTX* context = X509_STORE_CTX_new();
  X509_STORE_CTX_init(context, store, certificate.get(), nullptr);
  X509_STORE_CTX_set_purpose(context, purpose);
  const int ok = X509_verify_cert(context);
  const int error = ok == 1 ? X509_V_OK : X509_STORE_CTX_get_error(context);
  X509_STORE_CTX_free(context);
  X509_STORE_free(store);
  return error;
}

KeyAndCertificate Authority() {
  absl::StatusOr<KeyAndCertificate> ca =
      MakeCertificate({CertificateKind::kAuthority, "test CA", {}, -3600, 86400}, nullptr);
  EXPECT_TRUE(ca.ok()) << ca.status();
  return *ca;
}

TEST(Certificates, ServerAndClientCertificatesVerifyAgainstTheirAuthorityOnly) {
  const KeyAndCertificate ca = Authority();
  const KeyAndCertificate other_ca = Authority();
  absl::StatusOr<KeyAndCertificate> server =
      MakeCertificate({CertificateKind::kServer, "server", {"localhost", "127.0.0.1", "::1", "node7.cluster"}, -60,
                       86400},
                      &ca);
  ASSERT_TRUE(server.ok()) << server.status();
  absl::StatusOr<KeyAndCertificate> client =
      MakeCertificate({CertificateKind::kClient, "worker", {}, -60, 86400}, &ca);
  ASSERT_TRUE(client.ok()) << client.status();

  EXPECT_EQ(Verify(ca.certificate_pem, server->certificate_pem, X509_PURPOSE_SSL_SERVER), X509_V_OK);
  EXPECT_EQ(Verify(ca.certificate_pem, client->certificate_pem, X509_PURPOSE_SSL_CLIENT), X509_V_OK);
  // Each kind for its own use only.
  EXPECT_NE(Verify(ca.certificate_pem, client->certificate_pem, X509_PURPOSE_SSL_SERVER), X509_V_OK);
  EXPECT_NE(Verify(ca.certificate_pem, server->certificate_pem, X509_PURPOSE_SSL_CLIENT), X509_V_OK);
  // Another installation's authority does not vouch for them.
  EXPECT_NE(Verify(other_ca.certificate_pem, server->certificate_pem, X509_PURPOSE_SSL_SERVER), X509_V_OK);

  absl::StatusOr<CertificateInfo> info = InspectCertificate(server->certificate_pem, "server.pem");
  ASSERT_TRUE(info.ok()) << info.status();
  EXPECT_THAT(info->hosts, ElementsAre("localhost", "127.0.0.1", "::1", "node7.cluster"));
  EXPECT_THAT(info->subject, HasSubstr("CN=server"));
  EXPECT_FALSE(info->expired);
  EXPECT_FALSE(info->not_yet_valid);
  EXPECT_NEAR(static_cast<double>(info->seconds_left), 86400.0, 60.0);

  EXPECT_TRUE(CheckKeyMatchesCertificate(server->certificate_pem, server->key_pem, "s.pem", "s.key").ok());
  absl::Status mismatch = CheckKeyMatchesCertificate(server->certificate_pem, client->key_pem, "s.pem", "c.key");
  EXPECT_EQ(mismatch.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(mismatch.message()), HasSubstr("c.key is not the private key of the certificate s.pem"));
}

TEST(Certificates, ValidityIsReportedAndEnforcedByVerification) {
  const KeyAndCertificate ca = Authority();
  absl::StatusOr<KeyAndCertificate> expired =
      MakeCertificate({CertificateKind::kServer, "old", {"localhost"}, -7200, -3600}, &ca);
  ASSERT_TRUE(expired.ok()) << expired.status();
  absl::StatusOr<CertificateInfo> info = InspectCertificate(expired->certificate_pem, "old.pem");
  ASSERT_TRUE(info.ok());
  EXPECT_TRUE(info->expired);
  EXPECT_NEAR(static_cast<double>(info->seconds_left), -3600.0, 60.0);
  EXPECT_EQ(Verify(ca.certificate_pem, expired->certificate_pem, X509_PURPOSE_SSL_SERVER),
            X509_V_ERR_CERT_HAS_EXPIRED);

  absl::StatusOr<KeyAndCertificate> future =
      MakeCertificate({CertificateKind::kServer, "new", {"localhost"}, 3600, 7200}, &ca);
  ASSERT_TRUE(future.ok());
  EXPECT_TRUE(InspectCertificate(future->certificate_pem, "new.pem")->not_yet_valid);
}

TEST(Certificates, RequestsThatCannotWorkAreRefused) {
  const KeyAndCertificate ca = Authority();
  EXPECT_EQ(MakeCertificate({CertificateKind::kServer, "s", {}, -60, 60}, &ca).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(MakeCertificate({CertificateKind::kServer, "s", {"localhost"}, -60, 60}, nullptr).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(InspectCertificate("not a certificate", "x.pem").status().message()),
              HasSubstr("x.pem: no PEM certificate"));
}

}  // namespace
}  // namespace mbopt::auth
