#include "server/service/server.h"

#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include <grpcpp/resource_quota.h>

#include "absl/strings/str_cat.h"
#include "common/private_file.h"
#include "common/read_file.h"
#include "common/status_macros.h"
#include "server/auth/certificates.h"
#include "server/auth/token_table.h"
#include "server/lp/make_clp_lp_solver.h"
#include "server/service/audit_log.h"
#include "server/service/listen_address.h"
#include "server/service/proto_convert.h"
#include "server/service/token_metadata_processor.h"

namespace mbopt::service {
namespace {

// In-flight calls get this long to finish when the server stops; long polls
// and watches are woken before. gRPC also waits this long for clients that
// keep a connection open, so it bounds the time a stop takes.
constexpr auto kGrpcShutdownGrace = std::chrono::milliseconds(1000);
// The least time between two returns of freed memory to the system.
constexpr auto kTrimInterval = std::chrono::seconds(2);

absl::StatusOr<std::string> ReadPemFile(const std::string& path, const char* option) {
  absl::StatusOr<std::string> text = ReadWholeFile(path);
  if (!text.ok()) return absl::InvalidArgumentError(absl::StrCat(option, ": ", text.status().message()));
  return text;
}

}  // namespace

MboptServer::MboptServer(ServerOptions options) : options_(std::move(options)) {}

absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> MboptServer::LoadSecurity() {
  std::optional<auth::TokenTable> tokens;
  if (!options_.tokens_file.empty()) {
    MBOPT_ASSIGN_OR_RETURN(tokens, auth::TokenTable::Load(options_.tokens_file));
    MBOPT_RETURN_IF_ERROR(CheckSecretFileMode(options_.tokens_file, "the token table"));
    if (tokens->size() == 0) {
      return absl::InvalidArgumentError(
          absl::StrCat(options_.tokens_file, ": no tokens in the table: nobody could call the server"));
    }
  }
  const bool tls = !options_.tls_cert_file.empty() || !options_.tls_key_file.empty();
  if (!IsLoopbackAddress(options_.listen_address) && !options_.insecure && (!tls || !tokens)) {
    return absl::FailedPreconditionError(absl::StrCat(
        "refusing to listen on ", options_.listen_address, ": it is reachable from other machines, and ",
        !tls && !tokens ? "connections would have neither TLS nor tokens" : !tls ? "connections would have no TLS"
                                                                              : "callers would need no token",
        ": anyone who reaches the port could submit, read and cancel jobs and report results. Give --tls-dir DIR "
        "(made by `mbopt-server init-tls DIR`), or listen on 127.0.0.1, or pass --insecure on a network you trust "
        "(docs/server.md, \"Security\")"));
  }
  if (!options_.worker_ca_file.empty() && !tls) {
    return absl::InvalidArgumentError("--worker-ca verifies workers' certificates over TLS: it needs --tls-cert and "
                                      "--tls-key (or --tls-dir)");
  }
  authorizer_ = std::make_unique<CallAuthorizer>(std::move(tokens), !options_.worker_ca_file.empty());
  if (options_.max_calls_per_second_per_user > 0) {
    authorizer_->LimitUserCalls(options_.max_calls_per_second_per_user, [this] { return clock_->NowMs(); });
  }
  authorizer_->LimitHeldCallsPerPeer(options_.max_held_calls_per_peer);
  if (!tls) return grpc::InsecureServerCredentials();
  if (options_.tls_cert_file.empty() || options_.tls_key_file.empty()) {
    return absl::InvalidArgumentError("TLS needs both the certificate (--tls-cert) and its key (--tls-key)");
  }
  MBOPT_ASSIGN_OR_RETURN(std::string certificate, ReadPemFile(options_.tls_cert_file, "--tls-cert"));
  MBOPT_ASSIGN_OR_RETURN(std::string key, ReadPemFile(options_.tls_key_file, "--tls-key"));
  MBOPT_RETURN_IF_ERROR(CheckSecretFileMode(options_.tls_key_file, "the server's TLS key (--tls-key)"));
  MBOPT_RETURN_IF_ERROR(
      auth::CheckKeyMatchesCertificate(certificate, key, options_.tls_cert_file, options_.tls_key_file));
  MBOPT_ASSIGN_OR_RETURN(auth::CertificateInfo info, auth::InspectCertificate(certificate, options_.tls_cert_file));
  if (info.expired) {
    return absl::FailedPreconditionError(absl::StrCat("the server certificate ", options_.tls_cert_file,
                                                      " expired on ", info.not_after,
                                                      ": clients would refuse it. Make a new one (deploy/README.md)"));
  }
  grpc::SslServerCredentialsOptions ssl;
  ssl.pem_key_cert_pairs.push_back({key, certificate});
  if (!options_.worker_ca_file.empty()) {
    MBOPT_ASSIGN_OR_RETURN(ssl.pem_root_certs, ReadPemFile(options_.worker_ca_file, "--worker-ca"));
    MBOPT_RETURN_IF_ERROR(auth::InspectCertificate(ssl.pem_root_certs, options_.worker_ca_file).status());
    // Verified when given, not required: users' clients have none; worker
    // calls check for one (call_authorizer.h).
    ssl.client_certificate_request = GRPC_SSL_REQUEST_CLIENT_CERTIFICATE_AND_VERIFY;
  }
  std::shared_ptr<grpc::ServerCredentials> credentials = grpc::SslServerCredentials(ssl);
  if (authorizer_->needs_tokens()) {
    credentials->SetAuthMetadataProcessor(std::make_shared<TokenMetadataProcessor>(authorizer_.get()));
  }
  return credentials;
}

absl::StatusOr<std::unique_ptr<MboptServer>> MboptServer::Start(ServerOptions options) {
  std::unique_ptr<MboptServer> server(new MboptServer(std::move(options)));
  MboptServer& s = *server;
  MBOPT_ASSIGN_OR_RETURN(std::shared_ptr<grpc::ServerCredentials> credentials, s.LoadSecurity());
  if (s.options_.clock == nullptr) {
    s.own_clock_ = std::make_unique<scheduler::SteadyClock>();
    s.clock_ = s.own_clock_.get();
  } else {
    s.clock_ = s.options_.clock;
  }
  scheduler::SchedulerOptions scheduler_options;
  scheduler_options.lease_ms = s.options_.lease_ms;
  scheduler_options.heartbeat_interval_ms = s.options_.heartbeat_ms;
  MBOPT_RETURN_IF_ERROR(scheduler_options.Validate());
  MBOPT_ASSIGN_OR_RETURN(s.store_, store::Store::Open(s.options_.db_path, s.options_.durability));
  if (s.options_.before_result_commit) s.store_->SetBeforeCommitHook(s.options_.before_result_commit);
  s.scheduler_ = std::make_unique<scheduler::Scheduler>(s.clock_, scheduler_options);
  jobs::manager::JobManagerOptions manager_options = s.options_.manager;
  if (manager_options.clock == nullptr) manager_options.clock = s.clock_;
  if (manager_options.db_path_for_messages.empty()) manager_options.db_path_for_messages = s.options_.db_path;
  if (!manager_options.make_lp_solver) manager_options.make_lp_solver = [] { return lp::MakeClpLpSolver(); };
  s.manager_ = std::make_unique<jobs::manager::JobManager>(s.store_.get(), s.scheduler_.get(), &DecodeStudy, manager_options);
  MBOPT_RETURN_IF_ERROR(s.manager_->Start());

  s.job_service_ = std::make_unique<JobServiceImpl>(s.manager_.get(), s.authorizer_.get(), s.clock_);
  s.worker_service_ = std::make_unique<WorkerServiceImpl>(s.manager_.get(), s.scheduler_.get(), s.clock_,
                                                         s.options_.max_message_bytes, s.options_.max_result_bytes,
                                                         s.authorizer_.get());
  grpc::ServerBuilder builder;
  // Without this, gRPC on Linux binds with SO_REUSEPORT and a second server
  // on a port in use would silently share it instead of failing.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  builder.AddChannelArgument(GRPC_ARG_SERVER_HANDSHAKE_TIMEOUT_MS, static_cast<int>(s.options_.handshake_timeout_ms));
  builder.AddChannelArgument(GRPC_ARG_MAX_CONCURRENT_STREAMS, s.options_.max_streams_per_connection);
  grpc::ResourceQuota quota("mbopt-server");
  quota.SetMaxThreads(s.options_.max_call_threads);
  builder.SetResourceQuota(quota);
  builder.SetMaxReceiveMessageSize(static_cast<int>(s.options_.max_message_bytes));
  builder.SetMaxSendMessageSize(static_cast<int>(s.options_.max_message_bytes));
  builder.AddListeningPort(s.options_.listen_address, credentials, &s.port_);
  builder.RegisterService(s.job_service_.get());
  builder.RegisterService(s.worker_service_.get());
  s.grpc_server_ = builder.BuildAndStart();
  if (s.grpc_server_ == nullptr || s.port_ == 0) {
    return absl::UnavailableError(absl::StrCat("cannot listen on ", s.options_.listen_address,
                                               " (address in use or invalid?)"));
  }
  s.address_ = DialAddress(s.options_.listen_address, s.port_);

  const std::int64_t interval =
      s.options_.reaper_interval_ms > 0 ? s.options_.reaper_interval_ms : std::max<std::int64_t>(10, s.options_.lease_ms / 4);
  s.reaper_ = std::thread([&s, interval] { s.ReaperLoop(interval); });
  return server;
}

void MboptServer::ReaperLoop(std::int64_t interval_ms) {
  std::unique_lock<std::mutex> lock(reaper_mutex_);
  std::int64_t evictions_trimmed = 0;
  auto last_trim = std::chrono::steady_clock::now();
  while (!stopping_) {
    reaper_wake_.wait_for(lock, std::chrono::milliseconds(interval_ms), [this] { return stopping_; });
    if (stopping_) break;
    lock.unlock();
    manager_->ExpireLeases();
    // A finished job's memory is freed into the allocator's per-thread
    // arenas (gRPC serves calls on many threads), which keep it: without a
    // trim the server's resident size grows by about 10 KB per finished job
    // (docs/reliability.md). At most every few seconds, and only when jobs
    // stopped since the last one.
    const std::int64_t evictions = manager_->Evictions();
    const auto now = std::chrono::steady_clock::now();
    if (evictions != evictions_trimmed && now - last_trim >= kTrimInterval) {
      ::malloc_trim(0);
      evictions_trimmed = evictions;
      last_trim = now;
    }
    lock.lock();
  }
}

absl::StatusOr<std::size_t> MboptServer::ReloadTokens() {
  if (!authorizer_->needs_tokens()) {
    return absl::FailedPreconditionError("the server was started without a token table (--tokens or --tls-dir)");
  }
  // Deleting or emptying the table is a way to revoke every token: it must
  // not leave the old table in use.
  std::error_code error;
  if (!std::filesystem::exists(options_.tokens_file, error) && !error) {
    authorizer_->ReplaceTokens(auth::TokenTable());
    DropWorkersOfRevokedTokens(auth::TokenTable());
    return std::size_t{0};
  }
  MBOPT_ASSIGN_OR_RETURN(auth::TokenTable tokens, auth::TokenTable::Load(options_.tokens_file));
  // A table others may write could hold a token an attacker added.
  MBOPT_RETURN_IF_ERROR(CheckSecretFileMode(options_.tokens_file, "the token table"));
  const std::size_t count = tokens.size();
  authorizer_->ReplaceTokens(tokens);
  DropWorkersOfRevokedTokens(tokens);
  return count;
}

void MboptServer::DropWorkersOfRevokedTokens(const auth::TokenTable& tokens) {
  // A revoked worker's calls are refused from now on, so the tasks it holds
  // would wait out their leases: they are queued again at once, as for a
  // worker whose connection closed. Workers of the other tokens go on.
  std::set<std::string> revoked;
  for (const scheduler::WorkerView& worker : scheduler_->Workers()) {
    if (!worker.holder.empty() && !tokens.HasHolder({auth::Role::kWorker, worker.holder})) {
      revoked.insert(worker.holder);
    }
  }
  for (const std::string& holder : revoked) {
    for (const std::string& worker_id : scheduler_->WorkerIdsHeldBy(holder)) {
      AuditLog(absl::StrCat("worker ", scheduler::PublicWorkerId(worker_id), " dropped: its token (worker ", holder,
                            ") was revoked; the tasks it held are queued again"));
      manager_->WorkerLost(worker_id);
    }
  }
}

std::shared_ptr<grpc::Channel> MboptServer::InProcessChannel() {
  return grpc_server_->InProcessChannel(grpc::ChannelArguments());
}

void MboptServer::StopThreads() {
  {
    std::lock_guard<std::mutex> lock(reaper_mutex_);
    stopping_ = true;
  }
  reaper_wake_.notify_all();
  if (reaper_.joinable()) reaper_.join();
  scheduler_->Shutdown();
  if (grpc_server_ != nullptr) {
    grpc_server_->Shutdown(std::chrono::system_clock::now() + kGrpcShutdownGrace);
    grpc_server_->Wait();
  }
}

void MboptServer::Shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  manager_->Shutdown();
  StopThreads();
  manager_.reset();
  store_.reset();  // closes the database cleanly (checkpoints the WAL)
}

MboptServer::~MboptServer() {
  if (shut_down_ || manager_ == nullptr) return;
  // Not shut down: stop the threads but leave the jobs as they are in the
  // database, as a crash would.
  StopThreads();
}

}  // namespace mbopt::service
