// The optimizer server as one object: the job database, the scheduler, the
// job manager, the gRPC services and the lease reaper, wired together and
// started. Used by the mbopt-server executable and by in-process tests.
//
// Start() opens (or creates) the database, resumes the jobs that were running
// or interrupted, then listens. Shutdown() is the graceful stop: running jobs
// become INTERRUPTED (resumed on the next start), the listener stops and the
// database is closed. Destroying a server that was not shut down stops its
// threads but leaves the database as a crash would (jobs still RUNNING), which
// the next Start() recovers from the same way.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <grpcpp/grpcpp.h>

#include "absl/status/statusor.h"
#include "server/auth/token_table.h"
#include "server/scheduler/clock.h"
#include "server/scheduler/scheduler.h"
#include "server/service/grpc_services.h"
#include "server/jobs/manager/job_manager.h"
#include "server/store/store.h"

namespace mbopt::service {

struct ServerOptions {
  std::string listen_address = "127.0.0.1:50051";  // port 0: the OS picks
  // TLS: the server's certificate and key (PEM files); both or neither.
  std::string tls_cert_file;
  std::string tls_key_file;
  // With TLS: client certificates are verified against this CA, and worker
  // calls must come with one (mutual TLS for workers).
  std::string worker_ca_file;
  // The table of accepted tokens (server/auth/token_table.h); empty: none,
  // every caller may do everything.
  std::string tokens_file;
  // Allows an address reachable from other machines without TLS and
  // tokens (listen_address.h).
  bool insecure = false;
  std::string db_path = "mbopt.db";
  std::int64_t lease_ms = 30'000;
  std::int64_t heartbeat_ms = 5'000;
  // Not owned; nullptr: a monotonic clock. Tests pass a FakeClock.
  const scheduler::Clock* clock = nullptr;
  // Checks for expired leases run this often (real time); 0: lease_ms / 4.
  std::int64_t reaper_interval_ms = 0;
  // The largest message the server receives or sends (a study, a result, a
  // job's records); workers are told it when they register.
  std::int64_t max_message_bytes = std::int64_t{256} << 20;
  // The largest result the server takes, in pieces when it is over
  // max_message_bytes (the server holds it whole while it reassembles it);
  // workers are told it when they register.
  std::int64_t max_result_bytes = std::int64_t{1} << 30;
  // A connection that has not completed its TLS handshake and sent its
  // HTTP/2 settings this long after it was accepted is closed: idle
  // connections from anyone who reaches the port would otherwise hold a
  // descriptor each for gRPC's default of 120 s.
  std::int64_t handshake_timeout_ms = 10'000;
  // The most threads the server runs calls on (gRPC's resource quota): a
  // call that would need one more is refused with RESOURCE_EXHAUSTED, so
  // callers holding long calls open (watches, long polls) cannot make the
  // server start threads without end. Each worker holds about two (its
  // attach stream and its long poll), each watcher one.
  int max_call_threads = 1024;
  // The most calls one connection may have open at once (HTTP/2's
  // SETTINGS_MAX_CONCURRENT_STREAMS): further calls wait in the client.
  int max_streams_per_connection = 100;
  // The most calls held open (watches, attach streams, long polls, results
  // in pieces) by one peer address, so that one machine cannot take every
  // call thread; <= 0: no limit. A worker holds about 2.
  int max_held_calls_per_peer = 512;
  // JobService calls per second a user-role token may make (bursts of
  // twice that); 0: no limit. Admins and workers are not limited.
  double max_calls_per_second_per_user = 0;
  // What a machine crash may take from the job database (store.h).
  store::Durability durability = store::Durability::kCycles;
  jobs::manager::JobManagerOptions manager;
  // Testing: called inside each transaction of results before its COMMIT
  // (Store::SetBeforeCommitHook); empty: nothing.
  std::function<void(std::int64_t transaction)> before_result_commit;
};

class MboptServer {
 public:
  static absl::StatusOr<std::unique_ptr<MboptServer>> Start(ServerOptions options);
  ~MboptServer();
  MboptServer(const MboptServer&) = delete;
  MboptServer& operator=(const MboptServer&) = delete;

  int port() const { return port_; }
  // "host:port" as listening, with the port the OS picked.
  const std::string& address() const { return address_; }
  std::shared_ptr<grpc::Channel> InProcessChannel();
  jobs::manager::JobManager& manager() { return *manager_; }
  scheduler::Scheduler& scheduler() { return *scheduler_; }
  store::Store& store() { return *store_; }  // for tests

  // Reads the token table file again and uses it for the calls that start
  // after (SIGHUP of mbopt-server). Returns the number of tokens; 0 when the
  // file is missing or lists none: then every token is revoked and no call
  // is accepted until a table with tokens is read. On error (the file does
  // not parse, cannot be read, or others may read or write it) the table in
  // use stays.
  // Workers registered with a worker token that is no longer in the table
  // are dropped and their tasks queued again; the others go on.
  absl::StatusOr<std::size_t> ReloadTokens();

  // Graceful stop (see above). Idempotent.
  void Shutdown();

 private:
  explicit MboptServer(ServerOptions options);
  // The listening credentials and the authorizer, from the options' files.
  absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> LoadSecurity();
  void ReaperLoop(std::int64_t interval_ms);
  void StopThreads();
  void DropWorkersOfRevokedTokens(const auth::TokenTable& tokens);

  ServerOptions options_;
  std::unique_ptr<scheduler::SteadyClock> own_clock_;
  const scheduler::Clock* clock_ = nullptr;
  std::unique_ptr<store::Store> store_;
  std::unique_ptr<scheduler::Scheduler> scheduler_;
  std::unique_ptr<jobs::manager::JobManager> manager_;
  std::unique_ptr<CallAuthorizer> authorizer_;
  std::unique_ptr<JobServiceImpl> job_service_;
  std::unique_ptr<WorkerServiceImpl> worker_service_;
  std::unique_ptr<grpc::Server> grpc_server_;
  int port_ = 0;
  std::string address_;

  std::mutex reaper_mutex_;
  std::condition_variable reaper_wake_;
  bool stopping_ = false;
  std::thread reaper_;
  bool shut_down_ = false;
};

}  // namespace mbopt::service
