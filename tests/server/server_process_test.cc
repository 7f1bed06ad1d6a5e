// The mbopt-server executable as a process: its readiness line and port
// file, a clean stop on SIGTERM, and recovery from a SIGKILL in the middle of
// a job (--crash-after-cycles), checked bit for bit against an in-process run.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include "mbopt/v1/service.grpc.pb.h"
#include "server/auth/token_table.h"
#include "server/service/server.h"
#include "server/store/store.h"
#include "tests/server/fake_worker.h"
#include "tests/server/test_study.h"

namespace mbopt {
namespace {

using ::mbopt::testing::FakeWorker;
using ::mbopt::testing::OscillatorStudy;
using ::testing::HasSubstr;
using ::testing::StartsWith;

// The open-files limit of the server in the exhaustion tests: enough to
// start (gRPC's threads and pollers, the database) with room for a few
// dozen connections, far fewer than the test opens.
constexpr rlim_t kLowOpenFilesLimit = 96;
// Idle connections the test opens: well over the limit above.
constexpr int kFloodConnections = 200;
// How long the server may take to notice that its listener failed and stop.
constexpr int kListenerFailureNoticeMs = 20'000;

// Waits up to `timeout_ms` for `pid` to end (without reaping it); true if
// it did. A pidfd becomes readable when its process ends.
bool WaitForExit(pid_t pid, int timeout_ms) {
  const int pidfd = static_cast<int>(::syscall(SYS_pidfd_open, pid, 0));
  if (pidfd < 0) return false;
  pollfd watch{pidfd, POLLIN, 0};
  const int ready = ::poll(&watch, 1, timeout_ms);
  ::close(pidfd);
  return ready == 1;
}

// A TCP connection to 127.0.0.1:`port` that sends nothing; -1 on failure.
int IdleConnection(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// The soft open-files limit of process `pid`, from /proc.
long SoftOpenFilesLimit(pid_t pid) {
  std::ifstream limits("/proc/" + std::to_string(pid) + "/limits");
  std::string line;
  while (std::getline(limits, line)) {
    if (line.rfind("Max open files", 0) == 0) return std::strtol(line.c_str() + 14, nullptr, 10);
  }
  return -1;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A started mbopt-server and the first line it printed.
struct ServerProcess {
  pid_t pid = -1;
  std::string ready_line;
  int port = 0;

  // Waits for the process to end; returns its wait status.
  int Wait() {
    int status = 0;
    EXPECT_EQ(::waitpid(pid, &status, 0), pid);
    pid = -1;
    return status;
  }
  ~ServerProcess() {
    if (pid > 0) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
    }
  }
};

// How the process is started, beyond its arguments.
struct ProcessSetting {
  // Soft and hard open-files limits set before exec; 0: inherited.
  rlim_t open_files_soft = 0;
  rlim_t open_files_hard = 0;
  // The process's stderr goes here; "": inherited.
  std::string stderr_path;
};

std::unique_ptr<ServerProcess> StartServer(const std::vector<std::string>& args,
                                           const ProcessSetting& setting = {}) {
  int out[2];
  EXPECT_EQ(::pipe(out), 0);
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (setting.open_files_hard > 0) {
      const rlimit limit{setting.open_files_soft, setting.open_files_hard};
      if (::setrlimit(RLIMIT_NOFILE, &limit) != 0) ::_exit(126);
    }
    if (!setting.stderr_path.empty()) {
      const int err = ::open(setting.stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
      if (err < 0) ::_exit(126);
      ::dup2(err, STDERR_FILENO);
      ::close(err);
    }
    ::dup2(out[1], STDOUT_FILENO);
    ::close(out[0]);
    ::close(out[1]);
    std::vector<char*> argv;
    static std::string binary = MBOPT_SERVER_BINARY;
    argv.push_back(binary.data());
    std::vector<std::string> copies = args;
    for (std::string& a : copies) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(binary.c_str(), argv.data());
    ::_exit(127);
  }
  ::close(out[1]);
  auto process = std::make_unique<ServerProcess>();
  process->pid = pid;
  // Readiness: the one line on stdout (blocks until printed or the process ends).
  FILE* stream = ::fdopen(out[0], "r");
  char line[256] = {0};
  if (std::fgets(line, sizeof line, stream) != nullptr) process->ready_line = line;
  std::fclose(stream);
  const size_t colon = process->ready_line.rfind(':');
  if (colon != std::string::npos) process->port = std::atoi(process->ready_line.c_str() + colon + 1);
  return process;
}

class ServerProcessTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("mbopt_server_process_") + info->name() + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    db_ = (dir_ / "jobs.db").string();
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  static std::shared_ptr<grpc::Channel> Connect(int port) {
    return grpc::CreateChannel("127.0.0.1:" + std::to_string(port), grpc::InsecureChannelCredentials());
  }

  static std::string Submit(const std::shared_ptr<grpc::Channel>& channel) {
    auto stub = v1::JobService::NewStub(channel);
    grpc::ClientContext context;
    v1::SubmitJobRequest request;
    request.set_study(OscillatorStudy().SerializeAsString());
    v1::SubmitJobResponse response;
    grpc::Status status = stub->Submit(&context, request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response.job_id();
  }

  static v1::GetJobResponse Get(const std::shared_ptr<grpc::Channel>& channel, const std::string& id) {
    auto stub = v1::JobService::NewStub(channel);
    grpc::ClientContext context;
    v1::JobRef ref;
    ref.set_job_id(id);
    v1::GetJobResponse response;
    grpc::Status status = stub->Get(&context, ref, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response;
  }

  std::filesystem::path dir_;
  std::string db_;
};

TEST_F(ServerProcessTest, PrintsReadinessWritesPortFileAndStopsCleanlyOnSigterm) {
  const std::string port_file = (dir_ / "port").string();
  auto server = StartServer({"--listen", "127.0.0.1:0", "--db", db_, "--port-file", port_file});
  EXPECT_THAT(server->ready_line, StartsWith("mbopt-server listening on 127.0.0.1:"));
  ASSERT_GT(server->port, 0);
  std::ifstream in(port_file);
  int written = 0;
  in >> written;
  EXPECT_EQ(written, server->port);

  auto channel = Connect(server->port);
  const std::string id = Submit(channel);
  FakeWorker worker(channel, 1);
  EXPECT_EQ(worker.Run(4), 4);
  ASSERT_EQ(::kill(server->pid, SIGTERM), 0);
  const int status = server->Wait();
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);

  auto store = store::Store::Open(db_);
  ASSERT_TRUE(store.ok()) << store.status();
  auto job = (*store)->GetJob(id);
  ASSERT_TRUE(job.ok()) << job.status();
  EXPECT_EQ(job->state, "INTERRUPTED");
}

// Refused before anything is bound: the test opens no port off loopback.
TEST_F(ServerProcessTest, RefusesAnAddressOffLoopbackWithoutInsecure) {
  auto server = StartServer({"--listen", "0.0.0.0:0", "--db", db_});
  EXPECT_EQ(server->ready_line, "");
  const int status = server->Wait();
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  EXPECT_FALSE(std::filesystem::exists(db_)) << "refused before the database is touched";
}

TEST_F(ServerProcessTest, RefusesAGarbageDatabaseWithAClearError) {
  { std::ofstream(db_) << std::string(4096, 'z'); }
  auto server = StartServer({"--listen", "127.0.0.1:0", "--db", db_});
  EXPECT_EQ(server->ready_line, "");
  const int status = server->Wait();
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
}

TEST_F(ServerProcessTest, RaisesItsSoftOpenFilesLimitToTheHardLimit) {
  auto server = StartServer({"--listen", "127.0.0.1:0", "--db", db_}, {.open_files_soft = 64, .open_files_hard = 512, .stderr_path = ""});
  ASSERT_GT(server->port, 0);
  EXPECT_EQ(SoftOpenFilesLimit(server->pid), 512);
}

// Idle connections fill the server's descriptor table; gRPC 1.51 then
// stops accepting for good. The server must not stay up deaf: it stops
// with status 75 once gRPC's listener failed, so that systemd
// (Restart=on-failure) starts it again, and the restarted server answers.
TEST_F(ServerProcessTest, AFullDescriptorTableEndsTheServerForItsManagerToRestart) {
  const std::string log = (dir_ / "server.log").string();
  auto server = StartServer({"--listen", "127.0.0.1:0", "--db", db_},
                            {.open_files_soft = kLowOpenFilesLimit, .open_files_hard = kLowOpenFilesLimit,
                             .stderr_path = log});
  ASSERT_GT(server->port, 0);
  const std::string id = Submit(Connect(server->port));
  std::vector<int> connections;
  for (int i = 0; i < kFloodConnections; ++i) {
    const int fd = IdleConnection(server->port);
    if (fd >= 0) connections.push_back(fd);
  }
  EXPECT_GT(static_cast<rlim_t>(connections.size()), kLowOpenFilesLimit);
  const auto flooded = std::chrono::steady_clock::now();
  const bool ended = WaitForExit(server->pid, kListenerFailureNoticeMs);
  std::printf("%zu idle connections opened; the server ended %.2f s after the last\n", connections.size(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - flooded).count());
  for (int fd : connections) ::close(fd);
  ASSERT_TRUE(ended) << "the server stayed up after its listener failed; its log:\n" << ReadText(log);
  const int status = server->Wait();
  ASSERT_TRUE(WIFEXITED(status)) << ReadText(log);
  EXPECT_EQ(WEXITSTATUS(status), 75);
  EXPECT_THAT(ReadText(log), HasSubstr("gRPC stopped accepting connections (Failed accept4: Too many open files"));

  // What the service manager does: start it again. It answers, and the
  // job, interrupted by the stop, is there to resume.
  server = StartServer({"--listen", "127.0.0.1:0", "--db", db_});
  ASSERT_GT(server->port, 0);
  EXPECT_EQ(Get(Connect(server->port), id).summary().job_id(), id);
}

// Runs the server binary with `args` to its end; returns its exit status.
int RunServerCommand(const std::vector<std::string>& args) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv;
    static std::string binary = MBOPT_SERVER_BINARY;
    argv.push_back(binary.data());
    std::vector<std::string> copies = args;
    for (std::string& a : copies) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::execv(binary.c_str(), argv.data());
    ::_exit(127);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// A field of /proc/<pid>/status in bytes ("VmRSS", "VmHWM").
std::int64_t ProcessMemoryBytes(pid_t pid, const std::string& field) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::strtoll(line.c_str() + field.size() + 1, nullptr, 10) * 1024;
  }
  return -1;
}

// A Submit of 128 MB without a token, to a server with TLS and tokens as
// deploy/README.md sets it up: refused from its headers, before the
// message is read, so the server's peak memory does not grow by the
// message's size (it grew by more than twice that when the token was
// checked in the handler, after gRPC had read and decoded the message).
TEST_F(ServerProcessTest, ALargeCallWithoutATokenIsRefusedBeforeItsMessageIsRead) {
  constexpr std::int64_t kMessageBytes = std::int64_t{128} << 20;
  // What the server may grow by: HTTP/2 flow-control windows, TLS buffers,
  // gRPC's per-call state; a quarter of the message.
  constexpr std::int64_t kAllowedGrowthBytes = kMessageBytes / 4;
  const std::string pki = (dir_ / "pki").string();
  ASSERT_EQ(RunServerCommand({"init-tls", pki, "--host", "127.0.0.1"}), 0);
  const std::string log = (dir_ / "server.log").string();
  auto server = StartServer({"--listen", "127.0.0.1:0", "--tls-dir", pki, "--db", db_}, {.open_files_soft = 0, .open_files_hard = 0, .stderr_path = log});
  ASSERT_GT(server->port, 0) << ReadText(log);
  grpc::SslCredentialsOptions tls;
  tls.pem_root_certs = ReadText(pki + "/ca.pem");
  grpc::ChannelArguments arguments;
  arguments.SetMaxSendMessageSize(-1);
  std::shared_ptr<grpc::Channel> channel = grpc::CreateCustomChannel(
      "127.0.0.1:" + std::to_string(server->port), grpc::SslCredentials(tls), arguments);
  std::unique_ptr<v1::JobService::Stub> stub = v1::JobService::NewStub(channel);
  {
    // A first small call: the connection and its TLS session are set up
    // before the baseline is taken.
    grpc::ClientContext context;
    v1::ListJobsResponse response;
    EXPECT_EQ(stub->List(&context, v1::ListJobsRequest(), &response).error_code(),
              grpc::StatusCode::UNAUTHENTICATED);
  }
  const std::int64_t before = ProcessMemoryBytes(server->pid, "VmRSS");
  ASSERT_GT(before, 0);
  v1::SubmitJobRequest request;
  request.set_study(OscillatorStudy().SerializeAsString());
  request.set_source_name(std::string(static_cast<std::size_t>(kMessageBytes), 'x'));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
  v1::SubmitJobResponse response;
  const grpc::Status status = stub->Submit(&context, request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("needs a token"));
  const std::int64_t peak = ProcessMemoryBytes(server->pid, "VmHWM");
  // The figures docs/reliability.md quotes.
  std::printf("server resident before: %.1f MB, peak after a %lld MB call without a token: %.1f MB\n",
              before / 1048576.0, static_cast<long long>(kMessageBytes >> 20), peak / 1048576.0);
  EXPECT_LT(peak - before, kAllowedGrowthBytes)
      << "resident before " << before / 1048576 << " MB, peak after " << peak / 1048576 << " MB";
  EXPECT_THAT(ReadText(log), HasSubstr("audit: refused /mbopt.v1.JobService/Submit before reading its message"));
}

// `init-tls --worker NAME` makes one worker token per machine or Slurm
// array instead of the shared one, and `add-token worker NAME` adds one;
// a second token of a name already in the table is refused, so that
// removing a name's line revokes that worker alone.
TEST_F(ServerProcessTest, InitTlsAndAddTokenMakeOneWorkerTokenPerName) {
  const std::string pki = (dir_ / "pki").string();
  ASSERT_EQ(RunServerCommand({"init-tls", pki, "--host", "127.0.0.1", "--worker", "rack1", "--worker", "rack2"}), 0);
  EXPECT_FALSE(std::filesystem::exists(pki + "/worker.token")) << "no shared worker token with --worker";
  absl::StatusOr<auth::TokenTable> table = auth::TokenTable::Load(pki + "/tokens");
  ASSERT_TRUE(table.ok()) << table.status();
  EXPECT_EQ(table->size(), 3u);  // rack1, rack2, admin
  for (const char* name : {"rack1", "rack2"}) {
    const std::string token_file = pki + "/worker-" + name + ".token";
    ASSERT_TRUE(std::filesystem::exists(token_file)) << token_file;
    std::string token = ReadText(token_file);
    while (!token.empty() && token.back() == '\n') token.pop_back();
    const std::optional<auth::Principal> holder = table->Find(token);
    ASSERT_TRUE(holder.has_value()) << name;
    EXPECT_EQ(holder->role, auth::Role::kWorker);
    EXPECT_EQ(holder->name, name);
  }
  EXPECT_EQ(RunServerCommand({"init-tls", (dir_ / "twice").string(), "--worker", "rack1", "--worker", "rack1"}), 2);

  const std::string rack3 = (dir_ / "rack3.token").string();
  ASSERT_EQ(RunServerCommand({"add-token", "worker", "rack3", "--tokens", pki + "/tokens", "--out", rack3}), 0);
  table = auth::TokenTable::Load(pki + "/tokens");
  ASSERT_TRUE(table.ok()) << table.status();
  EXPECT_TRUE(table->HasHolder({auth::Role::kWorker, "rack3"}));
  EXPECT_EQ(table->size(), 4u);
  EXPECT_EQ(RunServerCommand({"add-token", "worker", "rack1", "--tokens", pki + "/tokens", "--out",
                              (dir_ / "again.token").string()}),
            1);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "again.token"));
  EXPECT_EQ(auth::TokenTable::Load(pki + "/tokens")->size(), 4u);
}

TEST_F(ServerProcessTest, KilledMidJobResumesOnRestartWithBitIdenticalRecords) {
  // Reference: the same study, uninterrupted, in process.
  v1::GetJobResponse reference;
  {
    service::ServerOptions options;
    options.listen_address = "127.0.0.1:0";
    options.db_path = (dir_ / "reference.db").string();
    auto server = service::MboptServer::Start(options);
    ASSERT_TRUE(server.ok()) << server.status();
    auto channel = (*server)->InProcessChannel();
    const std::string id = Submit(channel);
    FakeWorker worker(channel, 1);
    worker.Run();
    reference = Get(channel, id);
    ASSERT_EQ(reference.summary().state(), v1::JOB_STATE_CONVERGED);
    ASSERT_GT(reference.cycles_size(), 3);
    (*server)->Shutdown();
  }
  std::string id;
  {
    auto server = StartServer({"--listen", "127.0.0.1:0", "--db", db_, "--crash-after-cycles", "3"});
    ASSERT_GT(server->port, 0);
    auto channel = Connect(server->port);
    id = Submit(channel);
    FakeWorker worker(channel, 2);
    worker.TolerateServerLoss();
    worker.Run();
    EXPECT_TRUE(worker.failed());
    const int status = server->Wait();
    ASSERT_TRUE(WIFSIGNALED(status));
    EXPECT_EQ(WTERMSIG(status), SIGKILL);
  }
  auto server = StartServer({"--listen", "127.0.0.1:0", "--db", db_});
  ASSERT_GT(server->port, 0);
  auto channel = Connect(server->port);
  EXPECT_GE(Get(channel, id).cycles_size(), 3);
  FakeWorker worker(channel, 3);
  worker.Run();
  v1::GetJobResponse finished = Get(channel, id);
  EXPECT_EQ(finished.summary().state(), v1::JOB_STATE_CONVERGED);
  ASSERT_EQ(finished.cycles_size(), reference.cycles_size());
  for (int i = 0; i < finished.cycles_size(); ++i) {
    EXPECT_EQ(finished.cycles(i).SerializeAsString(), reference.cycles(i).SerializeAsString()) << "record " << i;
  }
  ::kill(server->pid, SIGTERM);
  const int status = server->Wait();
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

}  // namespace
}  // namespace mbopt
