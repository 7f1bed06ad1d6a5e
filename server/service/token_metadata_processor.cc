#include "server/service/token_metadata_processor.h"

#include <optional>
#include <string>
#include <string_view>

#include "absl/strings/str_cat.h"
#include "server/service/audit_log.h"

namespace mbopt::service {
namespace {

std::optional<std::string_view> Find(const grpc::AuthMetadataProcessor::InputMetadata& metadata,
                                     const char* key) {
  const auto it = metadata.find(key);
  if (it == metadata.end()) return std::nullopt;
  return std::string_view(it->second.data(), it->second.size());
}

}  // namespace

grpc::Status TokenMetadataProcessor::Process(const InputMetadata& auth_metadata, grpc::AuthContext*,
                                             OutputMetadata*, OutputMetadata*) {
  const absl::StatusOr<auth::Principal> principal =
      authorizer_->IdentifyBearer(Find(auth_metadata, "authorization"));
  if (principal.ok()) return grpc::Status::OK;
  // The peer's address is not known at this stage (gRPC gives the
  // processor the headers and the TLS identity only).
  const std::optional<std::string_view> path = Find(auth_metadata, ":path");
  const std::optional<std::string_view> agent = Find(auth_metadata, "user-agent");
  AuditLog(absl::StrCat("refused ", path ? std::string(*path) : std::string("a call"),
                        " before reading its message (user-agent '",
                        agent ? std::string(agent->substr(0, 128)) : std::string(), "'): ",
                        principal.status().message()));
  return grpc::Status(grpc::StatusCode::UNAUTHENTICATED, std::string(principal.status().message()));
}

}  // namespace mbopt::service
