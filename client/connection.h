// Where the CLI finds its server and how it reports RPC failures. The address
// comes from --server, else $MBOPT_SERVER, else 127.0.0.1:50051. Every gRPC
// error becomes one clear message and an exit code (exit_codes.h) here, and
// nowhere else.
#pragma once

#include <memory>
#include <string>

#include <grpcpp/grpcpp.h>

#include "common/secure_channel/client_security.h"
#include "mbopt/v1/service.grpc.pb.h"

namespace mbopt::client {

inline constexpr char kDefaultServerAddress[] = "127.0.0.1:50051";

// `flag_value` is the --server option ("" if not given).
std::string ResolveServerAddress(const std::string& flag_value);

// `security`: TLS and token (common/secure_channel); default: plaintext, no
// token, as for the private server of `mbopt run`.
std::unique_ptr<v1::JobService::Stub> ConnectJobService(const std::string& address,
                                                        const secure_channel::ClientSecurity& security = {});

// An RPC failure as the user should read it, e.g. "cannot reach server at
// 127.0.0.1:50051: failed to connect to all addresses" or "no job 'j-9' on
// server ...".
struct RpcFailure {
  std::string message;
  int exit_code = 0;
};
// With `security`, a connection that failed is examined to name the cause
// (a certificate not trusted, a port without TLS, ...).
RpcFailure DescribeRpcFailure(const grpc::Status& status, const std::string& address,
                              const secure_channel::ClientSecurity* security = nullptr);

// Deadline for the short unary calls (Submit, Get, List, Cancel, Resume): a
// guard against a hung server, not a pacing mechanism.
inline constexpr int kUnaryDeadlineSeconds = 30;
void SetUnaryDeadline(grpc::ClientContext* context);

// One job with its cycle history and study, as the server keeps it (a
// unary Get with the deadline above).
grpc::Status GetJob(v1::JobService::Stub& job_service, const std::string& job_id, v1::GetJobResponse* response);

}  // namespace mbopt::client
