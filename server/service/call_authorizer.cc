#include "server/service/call_authorizer.h"

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/service/audit_log.h"

namespace mbopt::service {
namespace {

constexpr std::string_view kBearer = "Bearer ";

}  // namespace

CallAuthorizer::CallAuthorizer(std::optional<auth::TokenTable> tokens, bool workers_need_certificate)
    : needs_tokens_(tokens.has_value()), workers_need_certificate_(workers_need_certificate) {
  if (tokens) tokens_ = std::make_shared<const auth::TokenTable>(*std::move(tokens));
}

void CallAuthorizer::ReplaceTokens(auth::TokenTable tokens) {
  auto table = std::make_shared<const auth::TokenTable>(std::move(tokens));
  std::lock_guard<std::mutex> lock(mutex_);
  tokens_ = std::move(table);
}

absl::StatusOr<auth::Principal> CallAuthorizer::Identify(const grpc::ServerContext& context) const {
  if (!needs_tokens_) return auth::Principal{auth::Role::kAdmin, ""};
  const auto& metadata = context.client_metadata();
  const auto header = metadata.find("authorization");
  if (header == metadata.end()) return IdentifyBearer(std::nullopt);
  return IdentifyBearer(std::string_view(header->second.data(), header->second.size()));
}

absl::StatusOr<auth::Principal> CallAuthorizer::IdentifyBearer(std::optional<std::string_view> header) const {
  if (!needs_tokens_) return auth::Principal{auth::Role::kAdmin, ""};
  std::shared_ptr<const auth::TokenTable> tokens;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    tokens = tokens_;
  }
  if (!header) {
    return absl::UnauthenticatedError(
        "this server needs a token with every call: give it with --token-file FILE or MBOPT_TOKEN_FILE "
        "(docs/server.md, \"Security\")");
  }
  const std::string_view value = *header;
  if (value.substr(0, kBearer.size()) != kBearer) {
    return absl::UnauthenticatedError("the authorization header is not `Bearer TOKEN`");
  }
  // The token itself is never put in a message: messages reach logs.
  std::optional<auth::Principal> principal = tokens->Find(value.substr(kBearer.size()));
  if (!principal) {
    return absl::UnauthenticatedError(
        "the token given is not one this server accepts (wrong token file, or the token was revoked)");
  }
  return *principal;
}

std::string CallAuthorizer::Caller(const grpc::ServerContext& context, const auth::Principal* principal) {
  if (principal == nullptr || principal->name.empty()) return absl::StrCat("peer ", context.peer());
  return absl::StrCat(auth::RoleName(principal->role), " ", principal->name, " (peer ", context.peer(), ")");
}

absl::Status CallAuthorizer::Refuse(const grpc::ServerContext& context, const char* method,
                                    const auth::Principal* principal, absl::Status why) {
  AuditLog(absl::StrCat("refused ", method, " from ", Caller(context, principal), ": ", why.message()));
  return why;
}

absl::StatusOr<auth::Principal> CallAuthorizer::ForJobs(const grpc::ServerContext& context,
                                                        const char* method) const {
  absl::StatusOr<auth::Principal> principal = Identify(context);
  if (!principal.ok()) return Refuse(context, method, nullptr, principal.status());
  if (principal->role == auth::Role::kWorker) {
    return Refuse(context, method, &*principal,
                  absl::PermissionDeniedError(absl::StrCat("a worker token may only acquire tasks and report results; ",
                                                           method, " needs a user or admin token")));
  }
  if (user_calls_ != nullptr && needs_tokens_ && principal->role == auth::Role::kUser &&
      !user_calls_->Allow(principal->name, now_ms_())) {
    // Not written to the audit log: a caller over the rate would fill it.
    return absl::ResourceExhaustedError(absl::StrFormat(
        "user '%s' makes more than %g calls per second (the server's --max-calls-per-second-per-user): slow down "
        "(`mbopt watch` follows a job with one call)",
        principal->name, user_calls_->calls_per_second()));
  }
  return principal;
}

void CallAuthorizer::LimitUserCalls(double calls_per_second, std::function<std::int64_t()> now_ms) {
  user_calls_ = std::make_unique<CallRateLimiter>(calls_per_second);
  now_ms_ = std::move(now_ms);
}

void CallAuthorizer::LimitHeldCallsPerPeer(int max_per_peer) {
  held_calls_ = max_per_peer > 0 ? std::make_unique<PeerCallLimiter>(max_per_peer) : nullptr;
}

absl::StatusOr<PeerCallLimiter::Slot> CallAuthorizer::HoldCall(const grpc::ServerContext& context,
                                                               const char* method) const {
  if (held_calls_ == nullptr) return PeerCallLimiter::Slot();
  absl::StatusOr<PeerCallLimiter::Slot> slot = held_calls_->Take(context.peer());
  if (!slot.ok()) return Refuse(context, method, nullptr, slot.status());
  return slot;
}

absl::StatusOr<auth::Principal> CallAuthorizer::ForWorkers(const grpc::ServerContext& context,
                                                           const char* method) const {
  absl::StatusOr<auth::Principal> principal = Identify(context);
  if (!principal.ok()) return Refuse(context, method, nullptr, principal.status());
  if (needs_tokens_ && principal->role != auth::Role::kWorker) {
    return Refuse(context, method, &*principal,
                  absl::PermissionDeniedError(absl::StrCat("a ", auth::RoleName(principal->role),
                                                           " token cannot act as a worker; ", method,
                                                           " needs a worker token")));
  }
  if (workers_need_certificate_) {
    const std::shared_ptr<const grpc::AuthContext> auth = context.auth_context();
    if (auth == nullptr || !auth->IsPeerAuthenticated()) {
      return Refuse(context, method, &*principal,
                    absl::UnauthenticatedError(absl::StrCat(
                        method, " needs a client certificate signed by the server's worker CA (mbopt-worker "
                                "--tls-cert and --tls-key)")));
    }
  }
  return principal;
}

bool CallAuthorizer::MaySee(const auth::Principal& principal, const std::string& owner) {
  return principal.role == auth::Role::kAdmin || principal.name == owner;
}

}  // namespace mbopt::service
