// Who is calling, and whether they may. Every call of the two services
// passes here first. A server without a token table lets every caller do
// everything (it listens on loopback, for its own machine's users); with
// one, each call must carry a token of the table (`authorization: Bearer
// TOKEN`), and its role decides:
//   JobService (submit, get, list, watch, cancel, resume): users and admins;
//     a user only on the jobs it submitted;
//   WorkerService (register, acquire tasks, report results, ...): workers,
//     and with a worker CA also a client certificate signed by it.
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include <grpcpp/grpcpp.h>

#include "absl/status/statusor.h"
#include "server/auth/principal.h"
#include "server/auth/token_table.h"
#include "server/service/call_rate_limiter.h"
#include "server/service/peer_call_limiter.h"

namespace mbopt::service {

class CallAuthorizer {
 public:
  // No table: everything is allowed. `workers_need_certificate`: the server
  // verifies client certificates against a worker CA and worker calls must
  // come with one.
  CallAuthorizer(std::optional<auth::TokenTable> tokens, bool workers_need_certificate);

  // The holder of the token in an `authorization` header's value
  // ("Bearer TOKEN"; nullopt: no such header). Unauthenticated, with words
  // for the client, without a token of the table. For the check before a
  // call's message is read (token_metadata_processor.h).
  absl::StatusOr<auth::Principal> IdentifyBearer(std::optional<std::string_view> header) const;

  // Whether calls need tokens (the authorizer was made with a table).
  bool needs_tokens() const { return needs_tokens_; }
  // Takes a new table (the server's SIGHUP), for calls that start after.
  // Only for an authorizer made with a table.
  void ReplaceTokens(auth::TokenTable tokens);

  // At most `calls_per_second` JobService calls per second (bursts of twice
  // that) from each user-role token holder, on the clock `now_ms`; admins
  // and workers are not limited, nor anyone on a server without tokens.
  void LimitUserCalls(double calls_per_second, std::function<std::int64_t()> now_ms);

  // At most `max_per_peer` calls held open (watches, attach streams, long
  // polls, results in pieces) per peer address; <= 0: no limit.
  void LimitHeldCallsPerPeer(int max_per_peer);
  // A place for a call that stays open (peer_call_limiter.h), or
  // ResourceExhausted (written to the audit log) when its address holds
  // its limit.
  absl::StatusOr<PeerCallLimiter::Slot> HoldCall(const grpc::ServerContext& context, const char* method) const;

  // The caller of a JobService method (`method` names it in messages).
  // Unauthenticated without a known token; PermissionDenied for a worker;
  // ResourceExhausted for a user over the call rate (LimitUserCalls).
  // Every refusal is written to the audit log (audit_log.h).
  absl::StatusOr<auth::Principal> ForJobs(const grpc::ServerContext& context, const char* method) const;
  // The caller of a WorkerService method: a worker, else as above.
  absl::StatusOr<auth::Principal> ForWorkers(const grpc::ServerContext& context, const char* method) const;

  // Who called, for the audit log: "user alice (peer ipv4:10.0.0.5:41234)",
  // or "peer ..." on a server without tokens or before the token is known.
  static std::string Caller(const grpc::ServerContext& context, const auth::Principal* principal);
  // Logs the refusal of `method` to the caller and returns `why`.
  static absl::Status Refuse(const grpc::ServerContext& context, const char* method,
                             const auth::Principal* principal, absl::Status why);

  // Whether `principal` may see, cancel or resume (and list) a job
  // submitted by `owner`.
  static bool MaySee(const auth::Principal& principal, const std::string& owner);

 private:
  absl::StatusOr<auth::Principal> Identify(const grpc::ServerContext& context) const;

  const bool needs_tokens_;
  const bool workers_need_certificate_;
  mutable std::mutex mutex_;
  std::shared_ptr<const auth::TokenTable> tokens_;  // null without tokens
  std::unique_ptr<CallRateLimiter> user_calls_;     // null: no limit
  std::unique_ptr<PeerCallLimiter> held_calls_;     // null: no limit
  std::function<std::int64_t()> now_ms_;
};

}  // namespace mbopt::service
