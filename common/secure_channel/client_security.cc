#include "common/secure_channel/client_security.h"

#include <cstdlib>
#include <utility>
#include <vector>

#include <grpc/support/log.h>
#include <grpcpp/security/credentials.h>
#include <grpcpp/support/client_interceptor.h>

#include "absl/status/status.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "common/private_file.h"
#include "common/read_file.h"

namespace mbopt::secure_channel {
namespace {

constexpr const char* kVariables[] = {"MBOPT_TLS_CA",          "MBOPT_TLS_CERT",   "MBOPT_TLS_KEY",
                                      "MBOPT_TLS_SERVER_NAME", "MBOPT_TOKEN_FILE", "MBOPT_TOKEN"};

// The option's value, else the variable's; `source` says which, for messages.
std::string Setting(const std::string& flag_value, const char* option, const char* variable, std::string* source) {
  if (!flag_value.empty()) {
    *source = option;
    return flag_value;
  }
  const char* env = std::getenv(variable);
  if (env != nullptr && env[0] != '\0') {
    *source = variable;
    return env;
  }
  return "";
}

absl::StatusOr<std::string> ReadFile(const std::string& path, const std::string& source) {
  absl::StatusOr<std::string> text = ReadWholeFile(path);
  if (!text.ok()) return absl::InvalidArgumentError(absl::StrCat(source, ": ", text.status().message()));
  return text;
}

class TokenInterceptor final : public grpc::experimental::Interceptor {
 public:
  explicit TokenInterceptor(const std::string* header) : header_(header) {}
  void Intercept(grpc::experimental::InterceptorBatchMethods* methods) override {
    if (methods->QueryInterceptionHookPoint(grpc::experimental::InterceptionHookPoints::PRE_SEND_INITIAL_METADATA)) {
      methods->GetSendInitialMetadata()->insert({"authorization", *header_});
    }
    methods->Proceed();
  }

 private:
  const std::string* header_;
};

class TokenInterceptorFactory final : public grpc::experimental::ClientInterceptorFactoryInterface {
 public:
  explicit TokenInterceptorFactory(const std::string& token) : header_("Bearer " + token) {}
  grpc::experimental::Interceptor* CreateClientInterceptor(grpc::experimental::ClientRpcInfo*) override {
    return new TokenInterceptor(&header_);
  }

 private:
  const std::string header_;  // lives as long as the channel, which owns the factory
};

}  // namespace

bool IsSecurityOption(const std::string& option) {
  ClientSecurityFlags ignored;
  return SetSecurityFlag(option, "", &ignored);
}

bool SetSecurityFlag(const std::string& option, const std::string& value, ClientSecurityFlags* flags) {
  if (option == "--tls-ca") {
    flags->tls_ca_file = value;
  } else if (option == "--tls-cert") {
    flags->tls_cert_file = value;
  } else if (option == "--tls-key") {
    flags->tls_key_file = value;
  } else if (option == "--tls-server-name") {
    flags->tls_server_name = value;
  } else if (option == "--token-file") {
    flags->token_file = value;
  } else {
    return false;
  }
  return true;
}

absl::StatusOr<ClientSecurity> LoadClientSecurity(const ClientSecurityFlags& flags) {
  ClientSecurity security;
  std::string ca_source, cert_source, key_source, name_source, token_file_source;
  const std::string ca_file = Setting(flags.tls_ca_file, "--tls-ca", "MBOPT_TLS_CA", &ca_source);
  const std::string cert_file = Setting(flags.tls_cert_file, "--tls-cert", "MBOPT_TLS_CERT", &cert_source);
  const std::string key_file = Setting(flags.tls_key_file, "--tls-key", "MBOPT_TLS_KEY", &key_source);
  security.server_name = Setting(flags.tls_server_name, "--tls-server-name", "MBOPT_TLS_SERVER_NAME", &name_source);
  if (!ca_file.empty()) {
    security.tls = true;
    security.ca_file = ca_file;
    auto pem = ReadFile(ca_file, ca_source);
    if (!pem.ok()) return pem.status();
    security.ca_pem = *std::move(pem);
  }
  if (cert_file.empty() != key_file.empty()) {
    return absl::InvalidArgumentError(cert_file.empty() ? absl::StrCat(key_source, " is set but no certificate: a client certificate needs --tls-cert (or MBOPT_TLS_CERT) too")
                                                        : absl::StrCat(cert_source, " is set but no key: a client certificate needs --tls-key (or MBOPT_TLS_KEY) too"));
  }
  if (!cert_file.empty()) {
    if (!security.tls) {
      return absl::InvalidArgumentError(absl::StrCat(
          cert_source, " is set but not --tls-ca (or MBOPT_TLS_CA): a client certificate is only used over TLS"));
    }
    auto cert = ReadFile(cert_file, cert_source);
    if (!cert.ok()) return cert.status();
    auto key = ReadFile(key_file, key_source);
    if (!key.ok()) return key.status();
    if (absl::Status mode = CheckSecretFileMode(key_file, absl::StrCat(key_source, ": the client key")); !mode.ok()) {
      return absl::InvalidArgumentError(mode.message());
    }
    security.cert_pem = *std::move(cert);
    security.key_pem = *std::move(key);
  }
  if (!security.server_name.empty() && !security.tls) {
    return absl::InvalidArgumentError(absl::StrCat(name_source, " is set but not --tls-ca (or MBOPT_TLS_CA)"));
  }
  const std::string token_file = Setting(flags.token_file, "--token-file", "MBOPT_TOKEN_FILE", &token_file_source);
  if (!token_file.empty()) {
    auto token = ReadFile(token_file, token_file_source);
    if (!token.ok()) return token.status();
    // A token others can read is a token others hold.
    if (absl::Status mode = CheckSecretFileMode(token_file, absl::StrCat(token_file_source, ": the token file"));
        !mode.ok()) {
      return absl::InvalidArgumentError(mode.message());
    }
    security.token = std::string(absl::StripAsciiWhitespace(*token));
    security.token_source = absl::StrCat(token_file_source, " ", token_file);
    if (security.token.empty()) {
      return absl::InvalidArgumentError(absl::StrCat(security.token_source, ": the file is empty"));
    }
  } else if (const char* env = std::getenv("MBOPT_TOKEN"); env != nullptr && env[0] != '\0') {
    security.token = std::string(absl::StripAsciiWhitespace(env));
    security.token_source = "MBOPT_TOKEN";
  }
  for (char c : security.token) {
    // A header value cannot hold control characters; a token never does.
    if (static_cast<unsigned char>(c) < 0x21 || c == 0x7f) {
      return absl::InvalidArgumentError(absl::StrCat(security.token_source,
                                                     ": the token holds a space or control character; it is one word "
                                                     "such as mbopt_3f2a..."));
    }
  }
  return security;
}

std::shared_ptr<grpc::Channel> CreateChannel(const std::string& address, const ClientSecurity& security,
                                             grpc::ChannelArguments args) {
  std::shared_ptr<grpc::ChannelCredentials> credentials;
  if (security.tls) {
    grpc::SslCredentialsOptions options;
    options.pem_root_certs = security.ca_pem;
    options.pem_private_key = security.key_pem;
    options.pem_cert_chain = security.cert_pem;
    credentials = grpc::SslCredentials(options);
    if (!security.server_name.empty()) args.SetSslTargetNameOverride(security.server_name);
  } else {
    credentials = grpc::InsecureChannelCredentials();
  }
  if (security.token.empty()) return grpc::CreateCustomChannel(address, credentials, args);
  std::vector<std::unique_ptr<grpc::experimental::ClientInterceptorFactoryInterface>> interceptors;
  interceptors.push_back(std::make_unique<TokenInterceptorFactory>(security.token));
  return grpc::experimental::CreateCustomChannelWithInterceptors(address, credentials, args, std::move(interceptors));
}

void QuietGrpcLogUnlessAsked() {
  const char* verbosity = std::getenv("GRPC_VERBOSITY");
  if (verbosity != nullptr && verbosity[0] != '\0') return;
  gpr_set_log_function([](gpr_log_func_args*) {});
}

void ClearSecurityEnvironment() {
  for (const char* variable : kVariables) ::unsetenv(variable);
}

}  // namespace mbopt::secure_channel
