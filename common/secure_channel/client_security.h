// The client side of a connection to an mbopt server, shared by the `mbopt`
// CLI and the worker: TLS (the server checked against a CA file, optionally
// a client certificate for mutual TLS) and the token sent with every call.
//
// Each setting comes from its option, else from the environment:
//   --tls-ca FILE           MBOPT_TLS_CA           CA certificate (PEM); TLS when set
//   --tls-cert / --tls-key  MBOPT_TLS_CERT / _KEY  client certificate and key (PEM)
//   --tls-server-name NAME  MBOPT_TLS_SERVER_NAME  the name to check the server's
//                                                  certificate against (through a tunnel)
//   --token-file FILE       MBOPT_TOKEN_FILE       the token, in a file
//                           MBOPT_TOKEN            the token itself
// A token is never taken from the command line: other users of the machine
// can read a process's arguments.
#pragma once

#include <memory>
#include <string>

#include <grpcpp/grpcpp.h>

#include "absl/status/statusor.h"

namespace mbopt::secure_channel {

// What the options said; empty strings: not given (the environment decides).
struct ClientSecurityFlags {
  std::string tls_ca_file;
  std::string tls_cert_file;
  std::string tls_key_file;
  std::string tls_server_name;
  std::string token_file;
};

// The settings as read, files loaded.
struct ClientSecurity {
  bool tls = false;
  std::string ca_file;  // for messages
  std::string ca_pem;
  std::string cert_pem;
  std::string key_pem;
  std::string server_name;  // "" : the host of the address
  std::string token;        // "" : none sent
  std::string token_source;  // for messages: "--token-file F", "MBOPT_TOKEN", ...
};

// The option names the CLI and the worker accept, each taking a value.
inline constexpr const char* kSecurityValueOptions[] = {"--tls-ca", "--tls-cert", "--tls-key", "--tls-server-name",
                                                        "--token-file"};

// Whether `option` is one of kSecurityValueOptions.
bool IsSecurityOption(const std::string& option);

// Sets the field of `flags` that `option` (one of kSecurityValueOptions)
// names. Returns false for another option.
bool SetSecurityFlag(const std::string& option, const std::string& value, ClientSecurityFlags* flags);

// Reads the files and the environment. InvalidArgument naming the option or
// variable and the file for anything missing, unreadable or inconsistent
// (a certificate without its key, an empty token).
absl::StatusOr<ClientSecurity> LoadClientSecurity(const ClientSecurityFlags& flags);

// A channel to `address` with these settings: TLS credentials or plaintext,
// and the token as an `authorization: Bearer` header on every call.
std::shared_ptr<grpc::Channel> CreateChannel(const std::string& address, const ClientSecurity& security,
                                             grpc::ChannelArguments args);

// Removes the variables above from this process's environment: programs
// that start a private server on loopback (`mbopt run`) must not hand the
// user's settings for another server to it or to its workers.
void ClearSecurityEnvironment();

// Drops gRPC's own log lines ("Handshake failed ...") unless GRPC_VERBOSITY
// asks for them: a client says what failed in one line of its own
// (connection_diagnosis.h), and a retrying worker would repeat them.
void QuietGrpcLogUnlessAsked();

}  // namespace mbopt::secure_channel
