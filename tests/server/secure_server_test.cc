// The server with TLS and tokens, on loopback, in process: who may call
// what, whose jobs each user sees, and what a client that lacks the CA, the
// token or the right certificate gets (and is told).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/secure_channel/client_security.h"
#include "common/secure_channel/connection_diagnosis.h"
#include "mbopt/v1/service.grpc.pb.h"
#include "server/auth/certificates.h"
#include "server/auth/token.h"
#include "server/auth/token_table.h"
#include "server/scheduler/clock.h"
#include "server/scheduler/scheduler.h"
#include "server/service/server.h"
#include "tests/server/fake_worker.h"
#include "tests/server/test_study.h"

namespace mbopt::service {
namespace {

using ::mbopt::testing::FakeWorker;
using ::mbopt::testing::OscillatorStudy;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

// A deadline for calls expected to fail at the connection: long enough for
// a handshake on a loaded machine, short enough to keep the test quick.
constexpr auto kConnectDeadline = std::chrono::seconds(10);

class SecureServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("mbopt_secure_") + info->name() + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    ca_ = Make({auth::CertificateKind::kAuthority, "test CA", {}, -3600, 86400}, nullptr);
    server_certificate_ = Make({auth::CertificateKind::kServer, "server", {"localhost", "127.0.0.1"}, -3600, 86400}, &ca_);
    worker_certificate_ = Make({auth::CertificateKind::kClient, "worker", {}, -3600, 86400}, &ca_);
    alice_ = *auth::NewToken();
    bob_ = *auth::NewToken();
    admin_ = *auth::NewToken();
    worker_ = *auth::NewToken();
    Write("tokens", auth::TokenTable::Line({auth::Role::kUser, "alice"}, alice_) +
                        auth::TokenTable::Line({auth::Role::kUser, "bob"}, bob_) +
                        auth::TokenTable::Line({auth::Role::kAdmin, "ops"}, admin_) +
                        auth::TokenTable::Line({auth::Role::kWorker, "workers"}, worker_));
  }
  void TearDown() override {
    server_.reset();
    std::filesystem::remove_all(dir_);
  }

  auth::KeyAndCertificate Make(const auth::CertificateRequest& request, const auth::KeyAndCertificate* issuer) {
    absl::StatusOr<auth::KeyAndCertificate> made = auth::MakeCertificate(request, issuer);
    EXPECT_TRUE(made.ok()) << made.status();
    return made.ok() ? *made : auth::KeyAndCertificate{};
  }
  // Readable by its owner only, as init-tls makes keys and tables;
  // `mode` for the files of the tests that see other modes refused.
  std::string Write(const std::string& name, const std::string& content,
                    std::filesystem::perms mode = std::filesystem::perms::owner_read |
                                                  std::filesystem::perms::owner_write) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << content;
    std::filesystem::permissions(path, mode);
    return path;
  }

  ServerOptions SecureOptions(const auth::KeyAndCertificate& certificate) {
    ServerOptions options;
    options.listen_address = "127.0.0.1:0";
    options.db_path = (dir_ / "jobs.db").string();
    options.tls_cert_file = Write("server.pem", certificate.certificate_pem);
    options.tls_key_file = Write("server.key", certificate.key_pem);
    options.tokens_file = (dir_ / "tokens").string();
    return options;
  }
  void StartServer(ServerOptions options) {
    absl::StatusOr<std::unique_ptr<MboptServer>> server = MboptServer::Start(std::move(options));
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = *std::move(server);
  }
  void StartSecureServer() { StartServer(SecureOptions(server_certificate_)); }

  // What a client with this CA (empty: plaintext), token and certificate has.
  secure_channel::ClientSecurity Client(const std::string& token, const std::string& ca_pem,
                                        const auth::KeyAndCertificate* certificate = nullptr) {
    secure_channel::ClientSecurity security;
    security.tls = !ca_pem.empty();
    security.ca_pem = ca_pem;
    security.ca_file = "ca.pem";
    security.token = token;
    if (certificate != nullptr) {
      security.cert_pem = certificate->certificate_pem;
      security.key_pem = certificate->key_pem;
    }
    return security;
  }
  std::shared_ptr<grpc::Channel> Channel(const secure_channel::ClientSecurity& security) {
    return secure_channel::CreateChannel(server_->address(), security, grpc::ChannelArguments());
  }
  std::unique_ptr<v1::JobService::Stub> Jobs(const std::string& token) {
    return v1::JobService::NewStub(Channel(Client(token, ca_.certificate_pem)));
  }

  static grpc::Status Submit(v1::JobService::Stub& jobs, std::string* job_id) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + kConnectDeadline);
    v1::SubmitJobRequest request;
    request.set_study(OscillatorStudy().SerializeAsString());
    v1::SubmitJobResponse response;
    grpc::Status status = jobs.Submit(&context, request, &response);
    *job_id = response.job_id();
    return status;
  }
  static grpc::Status Get(v1::JobService::Stub& jobs, const std::string& job_id, v1::GetJobResponse* response) {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + kConnectDeadline);
    v1::JobRef ref;
    ref.set_job_id(job_id);
    return jobs.Get(&context, ref, response);
  }
  static grpc::Status Cancel(v1::JobService::Stub& jobs, const std::string& job_id) {
    grpc::ClientContext context;
    v1::JobRef ref;
    ref.set_job_id(job_id);
    v1::JobSummary response;
    return jobs.Cancel(&context, ref, &response);
  }
  static v1::ListJobsResponse List(v1::JobService::Stub& jobs) {
    grpc::ClientContext context;
    v1::ListJobsResponse response;
    grpc::Status status = jobs.List(&context, v1::ListJobsRequest(), &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response;
  }

  std::filesystem::path dir_;
  auth::KeyAndCertificate ca_, server_certificate_, worker_certificate_;
  std::string alice_, bob_, admin_, worker_;
  std::unique_ptr<MboptServer> server_;
};

TEST_F(SecureServerTest, JobsRunOverTlsAndEachUserSeesOnlyTheirOwn) {
  StartSecureServer();
  auto alice = Jobs(alice_);
  auto bob = Jobs(bob_);
  auto admin = Jobs(admin_);
  std::string alices_job, bobs_job;
  ASSERT_TRUE(Submit(*alice, &alices_job).ok());
  ASSERT_TRUE(Submit(*bob, &bobs_job).ok());

  // A worker over TLS with the worker token runs both to the end.
  FakeWorker worker(Channel(Client(worker_, ca_.certificate_pem)), 1);
  worker.Run();
  v1::GetJobResponse job;
  ASSERT_TRUE(Get(*alice, alices_job, &job).ok());
  EXPECT_EQ(job.summary().state(), v1::JOB_STATE_CONVERGED) << job.summary().message();
  EXPECT_EQ(job.summary().owner(), "alice");

  // Bob can neither read nor cancel nor resume Alice's job, nor list it;
  // he is answered as for a job that does not exist, word for word, so ids
  // do not tell him which jobs exist.
  ::testing::internal::CaptureStderr();
  grpc::Status status = Get(*bob, alices_job, &job);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  const grpc::Status none = Get(*bob, "job-999", &job);
  EXPECT_EQ(none.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(status.error_message(), std::string(jobs::manager::JobManager::NoSuchJob(alices_job).message()));
  EXPECT_EQ(none.error_message(), std::string(jobs::manager::JobManager::NoSuchJob("job-999").message()));
  EXPECT_EQ(Cancel(*bob, alices_job).error_code(), grpc::StatusCode::NOT_FOUND);
  {
    grpc::ClientContext context;
    v1::JobRef ref;
    ref.set_job_id(alices_job);
    v1::JobSummary summary;
    EXPECT_EQ(bob->Resume(&context, ref, &summary).error_code(), grpc::StatusCode::NOT_FOUND);
  }
  {
    grpc::ClientContext context;
    v1::JobRef ref;
    ref.set_job_id(alices_job);
    auto stream = bob->Watch(&context, ref);
    v1::JobEvent event;
    EXPECT_FALSE(stream->Read(&event));
    EXPECT_EQ(stream->Finish().error_code(), grpc::StatusCode::NOT_FOUND);
  }
  // The log says what happened, and who tried.
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_THAT(log, HasSubstr("audit: refused Get from user bob (peer ipv4:127.0.0.1:"));
  EXPECT_THAT(log, HasSubstr("): job '" + alices_job + "' is another user's (alice)"));
  for (const char* method : {"Cancel", "Resume", "Watch"}) {
    EXPECT_THAT(log, HasSubstr(std::string("audit: refused ") + method + " from user bob")) << method;
  }
  const v1::ListJobsResponse bobs_list = List(*bob);
  ASSERT_EQ(bobs_list.jobs_size(), 1);
  EXPECT_EQ(bobs_list.jobs(0).job_id(), bobs_job);
  // The admin sees both.
  EXPECT_EQ(List(*admin).jobs_size(), 2);
  EXPECT_TRUE(Get(*admin, alices_job, &job).ok());
}

// Who submitted, cancelled and resumed a job is in its event log in the
// database, and in the server's audit log.
TEST_F(SecureServerTest, JobActionsNameWhoDidThemInTheJobsEventsAndTheAuditLog) {
  StartSecureServer();
  ::testing::internal::CaptureStderr();
  std::string job_id;
  ASSERT_TRUE(Submit(*Jobs(alice_), &job_id).ok());
  ASSERT_TRUE(Cancel(*Jobs(admin_), job_id).ok());
  {
    grpc::ClientContext context;
    v1::JobRef ref;
    ref.set_job_id(job_id);
    v1::JobSummary summary;
    ASSERT_TRUE(Jobs(alice_)->Resume(&context, ref, &summary).ok());
  }
  const std::string log = ::testing::internal::GetCapturedStderr();
  absl::StatusOr<std::vector<store::EventRow>> events = server_->store().LoadEvents(job_id);
  ASSERT_TRUE(events.ok()) << events.status();
  std::map<std::string, std::string> detail;
  for (const store::EventRow& e : *events) detail[e.kind] = e.message;
  EXPECT_THAT(detail["submitted"], HasSubstr("; by user alice (peer ipv4:127.0.0.1:"));
  EXPECT_THAT(detail["cancelled"], HasSubstr("by admin ops (peer ipv4:127.0.0.1:"));
  EXPECT_THAT(detail["resumed"], HasSubstr("resumed on request; by user alice (peer ipv4:127.0.0.1:"));
  EXPECT_THAT(log, HasSubstr("audit: submit " + job_id + " by user alice (peer ipv4:127.0.0.1:"));
  EXPECT_THAT(log, HasSubstr("audit: cancel " + job_id + " by admin ops (peer ipv4:127.0.0.1:"));
  EXPECT_THAT(log, HasSubstr("audit: resume " + job_id + " by user alice (peer ipv4:127.0.0.1:"));
  for (const std::string& token : {alice_, admin_}) {
    EXPECT_THAT(log, ::testing::Not(HasSubstr(token))) << "a token in the log";
    EXPECT_THAT(log, ::testing::Not(HasSubstr(auth::HashToken(token)))) << "a token's hash in the log";
  }
}

// A user polling in a tight loop is slowed down: after a burst of twice the
// rate, calls are RESOURCE_EXHAUSTED until the bucket refills; another user
// and an admin are not affected.
TEST_F(SecureServerTest, AUserOverTheCallRateIsSlowedDownAndNobodyElseIs) {
  scheduler::FakeClock clock;
  ServerOptions options = SecureOptions(server_certificate_);
  options.clock = &clock;
  options.max_calls_per_second_per_user = 2;
  StartServer(std::move(options));
  auto alice = Jobs(alice_);
  auto list = [](v1::JobService::Stub& jobs) {
    grpc::ClientContext context;
    v1::ListJobsResponse response;
    return jobs.List(&context, v1::ListJobsRequest(), &response);
  };
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(list(*alice).ok()) << i;  // the burst: twice the rate
  const grpc::Status over = list(*alice);
  EXPECT_EQ(over.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(over.error_message(), HasSubstr("user 'alice' makes more than 2 calls per second"));
  EXPECT_TRUE(list(*Jobs(bob_)).ok());
  for (int i = 0; i < 10; ++i) EXPECT_TRUE(list(*Jobs(admin_)).ok()) << i;
  clock.Advance(1000);  // two calls' worth
  EXPECT_TRUE(list(*alice).ok());
  EXPECT_TRUE(list(*alice).ok());
  EXPECT_EQ(list(*alice).error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
}

TEST_F(SecureServerTest, OnlyWorkerTokensActAsWorkersAndWorkerTokensCannotSubmit) {
  StartSecureServer();
  std::string job_id;
  ASSERT_TRUE(Submit(*Jobs(alice_), &job_id).ok());
  for (const std::string* token : {&alice_, &admin_}) {
    auto as_worker = v1::WorkerService::NewStub(Channel(Client(*token, ca_.certificate_pem)));
    {
      grpc::ClientContext context;
      v1::RegisterWorkerRequest request;
      request.set_name("impostor");
      request.set_slots(1);
      v1::RegisterWorkerResponse response;
      grpc::Status status = as_worker->Register(&context, request, &response);
      EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED);
      EXPECT_THAT(status.error_message(), HasSubstr("cannot act as a worker; Register needs a worker token"));
    }
    {
      grpc::ClientContext context;
      v1::TaskResult result;
      result.set_job_id(job_id);
      result.set_task_id(job_id + "/0/1");
      v1::ReportResultResponse response;
      grpc::Status status = as_worker->ReportResult(&context, result, &response);
      EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED);
      EXPECT_THAT(status.error_message(), HasSubstr("ReportResult needs a worker token"));
    }
  }
  std::string ignored;
  grpc::Status status = Submit(*Jobs(worker_), &ignored);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_THAT(status.error_message(), HasSubstr("a worker token may only acquire tasks and report results"));
}

// Users and admins may see which workers there are and what they can run
// (workers belong to the server, not to a job); what they see lets nobody
// act as a worker: the id's secret part is not shown. A worker token may
// not list them: it only acquires tasks and reports results.
TEST_F(SecureServerTest, WorkersAreListedToUsersAndAdminsWithTheirDriversButNotTheirSecretIds) {
  StartSecureServer();
  auto as_worker = v1::WorkerService::NewStub(Channel(Client(worker_, ca_.certificate_pem)));
  v1::RegisterWorkerResponse registered;
  {
    grpc::ClientContext context;
    v1::RegisterWorkerRequest request;
    request.set_name("sim-host");
    request.set_slots(2);
    request.add_drivers("quarter_car");
    ASSERT_TRUE(as_worker->Register(&context, request, &registered).ok());
  }
  for (const std::string* token : {&alice_, &admin_}) {
    grpc::ClientContext context;
    v1::ListWorkersResponse listed;
    ASSERT_TRUE(Jobs(*token)->ListWorkers(&context, v1::ListWorkersRequest(), &listed).ok());
    ASSERT_EQ(listed.workers_size(), 1);
    EXPECT_EQ(listed.workers(0).name(), "sim-host");
    EXPECT_EQ(listed.workers(0).slots(), 2);
    ASSERT_EQ(listed.workers(0).drivers_size(), 1);
    EXPECT_EQ(listed.workers(0).drivers(0), "quarter_car");
    EXPECT_EQ(listed.workers(0).id(), scheduler::PublicWorkerId(registered.worker_id()));
    EXPECT_NE(listed.workers(0).id(), registered.worker_id()) << "the secret part stays with the worker";
  }
  grpc::ClientContext context;
  v1::ListWorkersResponse listed;
  grpc::Status status = Jobs(worker_)->ListWorkers(&context, v1::ListWorkersRequest(), &listed);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED);
}

TEST_F(SecureServerTest, MissingOrWrongTokensAreRefusedAndReloadingTheTableRevokes) {
  StartSecureServer();
  std::string job_id;
  grpc::Status status = Submit(*Jobs(""), &job_id);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_THAT(status.error_message(), HasSubstr("needs a token"));
  status = Submit(*Jobs(*auth::NewToken()), &job_id);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_THAT(status.error_message(), HasSubstr("not one this server accepts"));

  // A new table: Bob revoked, Carol added; calls that start after see it.
  const std::string carol = *auth::NewToken();
  Write("tokens", auth::TokenTable::Line({auth::Role::kUser, "alice"}, alice_) +
                      auth::TokenTable::Line({auth::Role::kUser, "carol"}, carol));
  absl::StatusOr<std::size_t> reloaded = server_->ReloadTokens();
  ASSERT_TRUE(reloaded.ok()) << reloaded.status();
  EXPECT_EQ(*reloaded, 2u);
  EXPECT_EQ(Submit(*Jobs(bob_), &job_id).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_TRUE(Submit(*Jobs(carol), &job_id).ok());
  // A broken table is refused and the one in use stays.
  Write("tokens", "user carol not-a-hash\n");
  EXPECT_THAT(std::string(server_->ReloadTokens().status().message()), HasSubstr("tokens:1:"));
  EXPECT_TRUE(Submit(*Jobs(carol), &job_id).ok());
}

// Per-worker tokens: each machine (or Slurm array) has its own, so one can
// be revoked alone. The revoked worker's calls are refused and the tasks it
// held are queued again at once (not when their leases run out), while the
// other token's worker goes on and ends the job; every accepted batch of
// results is logged with the token's holder, and the job's analyses are
// counted by holder ("computed by").
TEST_F(SecureServerTest, EachWorkerTokenIsRevokedAloneAndTheJobSaysWhichTokensComputedIt) {
  const std::string rack1 = *auth::NewToken();
  const std::string rack2 = *auth::NewToken();
  const std::string users = auth::TokenTable::Line({auth::Role::kUser, "alice"}, alice_) +
                            auth::TokenTable::Line({auth::Role::kAdmin, "ops"}, admin_);
  Write("tokens", users + auth::TokenTable::Line({auth::Role::kWorker, "rack1"}, rack1) +
                      auth::TokenTable::Line({auth::Role::kWorker, "rack2"}, rack2));
  StartSecureServer();
  std::string job_id;
  ASSERT_TRUE(Submit(*Jobs(alice_), &job_id).ok());
  ::testing::internal::CaptureStderr();
  FakeWorker first(Channel(Client(rack1, ca_.certificate_pem)), 1, "node-a");
  FakeWorker second(Channel(Client(rack2, ca_.certificate_pem)), 2, "node-b");
  ASSERT_EQ(first.Run(2), 2);
  const std::vector<v1::AnalysisTask> held = first.Acquire(100);
  ASSERT_FALSE(held.empty()) << "the first worker must hold tasks when its token is revoked";
  {
    grpc::ClientContext context;
    v1::ListWorkersResponse listed;
    ASSERT_TRUE(Jobs(admin_)->ListWorkers(&context, v1::ListWorkersRequest(), &listed).ok());
    ASSERT_EQ(listed.workers_size(), 2);
    EXPECT_EQ(listed.workers(0).holder(), "rack1");
    EXPECT_EQ(listed.workers(1).holder(), "rack2");
  }

  Write("tokens", users + auth::TokenTable::Line({auth::Role::kWorker, "rack2"}, rack2));
  absl::StatusOr<std::size_t> reloaded = server_->ReloadTokens();
  ASSERT_TRUE(reloaded.ok()) << reloaded.status();
  EXPECT_EQ(*reloaded, 3u);
  bool accepted = true;
  EXPECT_EQ(first.Answer(held.front(), &accepted).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  // The lease is 30 s: the second worker gets the revoked one's tasks only
  // because they were queued again on the reload.
  second.Run();
  std::set<std::int64_t> answered_by_second(second.answered_request_ids().begin(),
                                            second.answered_request_ids().end());
  for (const v1::AnalysisTask& task : held) {
    EXPECT_TRUE(answered_by_second.count(task.request_id()) != 0) << "request " << task.request_id();
  }
  const std::string log = ::testing::internal::GetCapturedStderr();

  v1::GetJobResponse job;
  ASSERT_TRUE(Get(*Jobs(alice_), job_id, &job).ok());
  EXPECT_EQ(job.summary().state(), v1::JOB_STATE_CONVERGED) << job.summary().message();
  absl::StatusOr<std::vector<jobs::AnalysisRecord>> logged = server_->store().LoadAnalyses(job_id);
  ASSERT_TRUE(logged.ok()) << logged.status();
  std::map<std::string, std::int64_t> by_holder;
  for (const jobs::AnalysisRecord& analysis : *logged) ++by_holder[analysis.holder];
  EXPECT_EQ(by_holder, (std::map<std::string, std::int64_t>{{"rack1", 2}, {"rack2", static_cast<std::int64_t>(logged->size()) - 2}}));
  ASSERT_EQ(job.computed_by_size(), 2);
  EXPECT_EQ(job.computed_by(0).holder(), "rack1");
  EXPECT_EQ(job.computed_by(0).analyses(), 2);
  EXPECT_EQ(job.computed_by(1).holder(), "rack2");
  EXPECT_EQ(job.computed_by(1).analyses(), static_cast<std::int64_t>(logged->size()) - 2);

  const std::string first_id = scheduler::PublicWorkerId(first.worker_id());
  const std::string second_id = scheduler::PublicWorkerId(second.worker_id());
  EXPECT_THAT(log, HasSubstr(" of " + job_id + " taken from " + first_id + ", sent by worker rack1 (peer ipv4:"));
  EXPECT_THAT(log, HasSubstr(" taken from " + second_id + ", sent by worker rack2 (peer ipv4:"));
  EXPECT_THAT(log, HasSubstr("audit: worker " + first_id + " dropped: its token (worker rack1) was revoked"));
  EXPECT_THAT(log, ::testing::Not(HasSubstr("worker " + second_id + " dropped")));
  {
    grpc::ClientContext context;
    v1::ListWorkersResponse listed;
    ASSERT_TRUE(Jobs(admin_)->ListWorkers(&context, v1::ListWorkersRequest(), &listed).ok());
    ASSERT_EQ(listed.workers_size(), 1);
    EXPECT_EQ(listed.workers(0).id(), second_id);
  }
}

TEST_F(SecureServerTest, ATokenTableOrKeyOthersMayReadOrWriteIsRefusedAtStart) {
  using std::filesystem::perms;
  const perms kOwner = perms::owner_read | perms::owner_write;
  // A table anyone may write: anyone could add an admin token's hash.
  ServerOptions options = SecureOptions(server_certificate_);
  std::filesystem::permissions(options.tokens_file, kOwner | perms::others_write);
  absl::StatusOr<std::unique_ptr<MboptServer>> server = MboptServer::Start(options);
  ASSERT_FALSE(server.ok());
  EXPECT_EQ(server.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(server.status().message(),
              HasSubstr("the token table " + options.tokens_file + " has mode 0602: writable by every user"));
  EXPECT_THAT(server.status().message(), HasSubstr("chmod 600 " + options.tokens_file));
  // A key the group may write, and one anyone may read.
  std::filesystem::permissions(options.tokens_file, kOwner);
  for (const perms extra : {perms::group_write, perms::others_read}) {
    std::filesystem::permissions(options.tls_key_file, kOwner | extra);
    server = MboptServer::Start(options);
    ASSERT_FALSE(server.ok());
    EXPECT_THAT(server.status().message(), HasSubstr("the server's TLS key (--tls-key) " + options.tls_key_file));
    EXPECT_THAT(server.status().message(), HasSubstr("chmod 600"));
  }
  // Fixed, it starts.
  std::filesystem::permissions(options.tls_key_file, kOwner);
  StartServer(options);
}

TEST_F(SecureServerTest, ReloadingAnEmptyOrMissingTableRevokesEveryToken) {
  using std::filesystem::perms;
  StartSecureServer();
  std::string job_id;
  ASSERT_TRUE(Submit(*Jobs(alice_), &job_id).ok());
  Write("tokens", "# every token revoked\n");
  absl::StatusOr<std::size_t> reloaded = server_->ReloadTokens();
  ASSERT_TRUE(reloaded.ok()) << reloaded.status();
  EXPECT_EQ(*reloaded, 0u);
  EXPECT_EQ(Submit(*Jobs(alice_), &job_id).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_EQ(Submit(*Jobs(admin_), &job_id).error_code(), grpc::StatusCode::UNAUTHENTICATED);

  // Back, then deleted.
  Write("tokens", auth::TokenTable::Line({auth::Role::kUser, "alice"}, alice_));
  ASSERT_EQ(server_->ReloadTokens().value_or(99), 1u);
  EXPECT_TRUE(Submit(*Jobs(alice_), &job_id).ok());
  std::filesystem::remove(dir_ / "tokens");
  reloaded = server_->ReloadTokens();
  ASSERT_TRUE(reloaded.ok()) << reloaded.status();
  EXPECT_EQ(*reloaded, 0u);
  EXPECT_EQ(Submit(*Jobs(alice_), &job_id).error_code(), grpc::StatusCode::UNAUTHENTICATED);

  // A table others may write is not taken: the one in use stays.
  Write("tokens", auth::TokenTable::Line({auth::Role::kUser, "alice"}, alice_),
        perms::owner_read | perms::owner_write | perms::others_write);
  EXPECT_THAT(std::string(server_->ReloadTokens().status().message()), HasSubstr("has mode 0602"));
  EXPECT_EQ(Submit(*Jobs(alice_), &job_id).error_code(), grpc::StatusCode::UNAUTHENTICATED);
}

TEST_F(SecureServerTest, ClientsWithoutTheCaOrWithPlaintextCannotConnectAndAreToldWhy) {
  StartSecureServer();
  // Plaintext, with a valid token: refused at the connection.
  std::string job_id;
  auto plaintext = v1::JobService::NewStub(Channel(Client(alice_, "")));
  EXPECT_EQ(Submit(*plaintext, &job_id).error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_THAT(secure_channel::DiagnoseConnectionFailure(server_->address(), Client(alice_, "")),
              HasSubstr("speaks TLS: give its CA certificate with --tls-ca"));
  // TLS trusting another installation's CA.
  const auth::KeyAndCertificate other_ca = Make({auth::CertificateKind::kAuthority, "other", {}, -60, 86400}, nullptr);
  auto wrong_ca = v1::JobService::NewStub(Channel(Client(alice_, other_ca.certificate_pem)));
  EXPECT_EQ(Submit(*wrong_ca, &job_id).error_code(), grpc::StatusCode::UNAVAILABLE);
  EXPECT_THAT(secure_channel::DiagnoseConnectionFailure(server_->address(), Client(alice_, other_ca.certificate_pem)),
              HasSubstr("is not signed by the CA in ca.pem"));
  // The right CA: nothing to diagnose.
  EXPECT_THAT(secure_channel::DiagnoseConnectionFailure(server_->address(), Client(alice_, ca_.certificate_pem)),
              IsEmpty());
  EXPECT_TRUE(Submit(*Jobs(alice_), &job_id).ok());
}

// A connection that never starts its TLS handshake holds a descriptor of
// the server; it is closed after the handshake timeout, not gRPC's 120 s.
TEST_F(SecureServerTest, AnIdleConnectionWithoutHandshakeIsClosedAfterTheHandshakeTimeout) {
  constexpr std::int64_t kHandshakeTimeoutMs = 300;
  // Far above the timeout (slow machines), far below gRPC's default 120 s.
  constexpr int kCloseWithinMs = 20'000;
  ServerOptions options = SecureOptions(server_certificate_);
  options.handshake_timeout_ms = kHandshakeTimeoutMs;
  StartServer(options);
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(server_->port()));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  const auto start = std::chrono::steady_clock::now();
  pollfd closed{fd, POLLIN, 0};
  ASSERT_EQ(::poll(&closed, 1, kCloseWithinMs), 1) << "still open after " << kCloseWithinMs << " ms";
  char byte = 0;
  EXPECT_LE(::recv(fd, &byte, 1, 0), 0) << "closed, without a byte";
  EXPECT_GE(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(kHandshakeTimeoutMs / 2));
  ::close(fd);
}

TEST_F(SecureServerTest, NoPlaintextHttp2IsAnsweredOnTheTlsPort) {
  StartSecureServer();
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(server_->port()));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  timeval timeout{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  // An HTTP/2 client's preface and an empty SETTINGS frame, in the clear.
  const std::string preface = std::string("PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n") + std::string("\0\0\0\4\0\0\0\0\0", 9);
  ASSERT_EQ(::send(fd, preface.data(), preface.size(), MSG_NOSIGNAL), static_cast<ssize_t>(preface.size()));
  char reply[64] = {};
  const ssize_t got = ::recv(fd, reply, sizeof reply, 0);
  ::close(fd);
  // A plaintext HTTP/2 server answers with its SETTINGS frame (type 4 in the
  // fourth byte); a TLS server closes, or sends a TLS alert (record type 21).
  if (got >= 4) {
    EXPECT_NE(reply[3], 4) << "the TLS port answered plaintext HTTP/2";
    EXPECT_EQ(static_cast<unsigned char>(reply[0]), 21u) << "neither closed nor a TLS alert";
  } else {
    EXPECT_LE(got, 0);
  }
}

TEST_F(SecureServerTest, ACertificateForOtherHostsOrExpiredIsNamed) {
  const auth::KeyAndCertificate elsewhere =
      Make({auth::CertificateKind::kServer, "elsewhere", {"build7.example"}, -3600, 86400}, &ca_);
  StartServer(SecureOptions(elsewhere));
  EXPECT_THAT(secure_channel::DiagnoseConnectionFailure(server_->address(), Client(alice_, ca_.certificate_pem)),
              HasSubstr("the server's certificate (for build7.example) is not made for '127.0.0.1'"));
  // Through a tunnel, the name the certificate carries is given explicitly.
  secure_channel::ClientSecurity tunnel = Client(alice_, ca_.certificate_pem);
  tunnel.server_name = "build7.example";
  std::string job_id;
  EXPECT_TRUE(Submit(*v1::JobService::NewStub(Channel(tunnel)), &job_id).ok());
  server_.reset();

  const auth::KeyAndCertificate expired =
      Make({auth::CertificateKind::kServer, "old", {"127.0.0.1"}, -7200, -3600}, &ca_);
  absl::StatusOr<std::unique_ptr<MboptServer>> refused = MboptServer::Start(SecureOptions(expired));
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(std::string(refused.status().message()), HasSubstr("server.pem expired on"));

  ServerOptions mismatched = SecureOptions(server_certificate_);
  mismatched.tls_key_file = Write("other.key", worker_certificate_.key_pem);
  refused = MboptServer::Start(mismatched);
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(std::string(refused.status().message()), HasSubstr("other.key is not the private key of the certificate"));
}

TEST_F(SecureServerTest, WithAWorkerCaWorkersNeedACertificateAndUsersDoNot) {
  ServerOptions options = SecureOptions(server_certificate_);
  options.worker_ca_file = Write("ca.pem", ca_.certificate_pem);
  StartServer(options);
  auto register_worker = [&](const secure_channel::ClientSecurity& security) {
    auto stub = v1::WorkerService::NewStub(Channel(security));
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + kConnectDeadline);
    v1::RegisterWorkerRequest request;
    request.set_name("w");
    request.set_slots(1);
    v1::RegisterWorkerResponse response;
    return stub->Register(&context, request, &response);
  };
  grpc::Status status = register_worker(Client(worker_, ca_.certificate_pem));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_THAT(status.error_message(), HasSubstr("needs a client certificate signed by the server's worker CA"));
  EXPECT_TRUE(register_worker(Client(worker_, ca_.certificate_pem, &worker_certificate_)).ok());
  // A certificate from another CA does not get through the handshake.
  const auth::KeyAndCertificate other_ca = Make({auth::CertificateKind::kAuthority, "other", {}, -60, 86400}, nullptr);
  const auth::KeyAndCertificate foreign = Make({auth::CertificateKind::kClient, "foreign", {}, -60, 86400}, &other_ca);
  EXPECT_EQ(register_worker(Client(worker_, ca_.certificate_pem, &foreign)).error_code(),
            grpc::StatusCode::UNAVAILABLE);
  // Users' clients have no certificate and need none.
  std::string job_id;
  EXPECT_TRUE(Submit(*Jobs(alice_), &job_id).ok());
}

TEST_F(SecureServerTest, AnAddressOtherMachinesReachNeedsTlsAndTokens) {
  // Refused before anything listens: no socket is opened off loopback.
  ServerOptions options;
  options.listen_address = "0.0.0.0:0";
  options.db_path = (dir_ / "jobs.db").string();
  absl::StatusOr<std::unique_ptr<MboptServer>> refused = MboptServer::Start(options);
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(std::string(refused.status().message()), HasSubstr("neither TLS nor tokens"));
  options.tokens_file = (dir_ / "tokens").string();
  refused = MboptServer::Start(options);
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(std::string(refused.status().message()), HasSubstr("connections would have no TLS"));
  options = SecureOptions(server_certificate_);
  options.listen_address = "0.0.0.0:0";
  options.tokens_file.clear();
  refused = MboptServer::Start(options);
  ASSERT_FALSE(refused.ok());
  EXPECT_THAT(std::string(refused.status().message()), HasSubstr("callers would need no token"));
}

}  // namespace
}  // namespace mbopt::service
