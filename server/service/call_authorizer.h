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

#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <grpcpp/grpcpp.h>

#include "absl/status/statusor.h"
#include "server/auth/principal.h"
#include "server/auth/token_table.h"

namespace mbopt::service {

class CallAuthorizer {
 public:
  // No table: everything is allowed. `workers_need_certificate`: the server
  // verifies client certificates against a worker CA and worker calls must
  // come with one.
  CallAuthorizer(std::optional<auth::TokenTable> tokens, bool workers_need_certificate);

  // Whether calls need tokens (the authorizer was made with a table).
  bool needs_tokens() const { return needs_tokens_; }
  // Takes a new table (the server's SIGHUP), for calls that start after.
  // Only for an authorizer made with a table.
  void ReplaceTokens(auth::TokenTable tokens);

  // The caller of a JobService method (`method` names it in messages).
  // Unauthenticated without a known token; PermissionDenied for a worker.
  absl::StatusOr<auth::Principal> ForJobs(const grpc::ServerContext& context, const char* method) const;
  // The caller of a WorkerService method: a worker, else as above.
  absl::StatusOr<auth::Principal> ForWorkers(const grpc::ServerContext& context, const char* method) const;

  // PermissionDenied unless `principal` may read, cancel or resume the job
  // `job_id` submitted by `owner`.
  static absl::Status CheckMaySee(const auth::Principal& principal, const std::string& job_id,
                                  const std::string& owner);
  // Whether a job of `owner` is listed for `principal`.
  static bool MaySee(const auth::Principal& principal, const std::string& owner);

 private:
  absl::StatusOr<auth::Principal> Identify(const grpc::ServerContext& context) const;

  const bool needs_tokens_;
  const bool workers_need_certificate_;
  mutable std::mutex mutex_;
  std::shared_ptr<const auth::TokenTable> tokens_;  // null without tokens
};

}  // namespace mbopt::service
