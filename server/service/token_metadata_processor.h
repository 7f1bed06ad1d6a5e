// The token check before a call's message is read. gRPC's sync server
// receives a unary call's whole message before its handler runs, so a check
// in the handler (CallAuthorizer) comes after the server has taken and
// decoded up to --max-message-mb from anyone who reaches the port. This
// processor runs in gRPC's authentication filter on the call's headers
// alone: a call without a token of the table is ended there, UNAUTHENTICATED
// with CallAuthorizer's words, and its message is never read (what the
// client had sent within HTTP/2's flow-control window is dropped with the
// stream). The handlers still authorize every call (roles, job owners,
// worker certificates); this is the first gate, not the only one.
//
// gRPC runs such processors only on secure (TLS) ports; a server with
// tokens but without TLS (loopback) checks in the handlers only.
#pragma once

#include <grpcpp/security/auth_metadata_processor.h>

#include "server/service/call_authorizer.h"

namespace mbopt::service {

class TokenMetadataProcessor final : public grpc::AuthMetadataProcessor {
 public:
  // `authorizer` is not owned and must outlive the server; it must have
  // a token table.
  explicit TokenMetadataProcessor(const CallAuthorizer* authorizer) : authorizer_(authorizer) {}

  // A hash and a table lookup: run on gRPC's thread, not a separate one.
  bool IsBlocking() const override { return false; }

  grpc::Status Process(const InputMetadata& auth_metadata, grpc::AuthContext* context,
                       OutputMetadata* consumed_auth_metadata, OutputMetadata* response_metadata) override;

 private:
  const CallAuthorizer* authorizer_;
};

}  // namespace mbopt::service
