#include "client/local_cluster.h"

#include <signal.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "common/read_file.h"
#include "common/secure_channel/client_security.h"

namespace mbopt::client {
namespace {

constexpr char kReadyPrefix[] = "mbopt-server listening on ";
constexpr auto kStopGrace = std::chrono::seconds(20);

bool IsExecutable(const std::string& path) {
  return !path.empty() && access(path.c_str(), X_OK) == 0 &&
         !std::filesystem::is_directory(path);
}

}  // namespace

absl::StatusOr<std::string> FindMboptBinary(const std::string& name, const char* env_var,
                                            const std::string& build_subdir) {
  if (const char* env = std::getenv(env_var); env != nullptr && env[0] != '\0') {
    if (IsExecutable(env)) return std::string(env);
    return absl::NotFoundError(absl::StrCat("$", env_var, " = ", env, " is not an executable"));
  }
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return absl::NotFoundError(absl::StrCat("cannot locate ", name, ": ", ec.message()));
  const auto dir = self.parent_path();
  const std::string candidates[] = {(dir / name).string(),
                                    (dir.parent_path() / build_subdir / name).string()};
  for (const auto& c : candidates) {
    if (IsExecutable(c)) return c;
  }
  return absl::NotFoundError(absl::StrCat("cannot find ", name, " (looked at ", candidates[0],
                                          " and ", candidates[1], "; set $", env_var, ")"));
}

absl::StatusOr<std::string> ParseListeningLine(const std::string& line) {
  if (!absl::StartsWith(line, kReadyPrefix)) {
    return absl::InvalidArgumentError(absl::StrCat("unexpected server output: '", line, "'"));
  }
  std::string address = line.substr(sizeof kReadyPrefix - 1);
  while (!address.empty() && (address.back() == '\r' || address.back() == ' ')) {
    address.pop_back();
  }
  if (address.find(':') == std::string::npos) {
    return absl::InvalidArgumentError(absl::StrCat("no port in server output: '", line, "'"));
  }
  return address;
}

absl::StatusOr<std::unique_ptr<LocalCluster>> LocalCluster::Start(
    const LocalClusterOptions& options) {
  // The private server has neither TLS nor tokens: settings in this
  // process's environment meant for another server must not reach the
  // workers started below (nor this process's own connection to it).
  secure_channel::ClearSecurityEnvironment();
  std::unique_ptr<LocalCluster> cluster(new LocalCluster());
  cluster->options_ = options;
  SpawnOptions server_spawn;
  server_spawn.capture_stdout = true;
  server_spawn.stderr_path = options.log_dir + "/server.log";
  std::vector<std::string> server_args = {options.server_binary, "--listen", "127.0.0.1:0", "--db",
                                          options.db_path,        "--port-file", options.log_dir + "/port"};
  if (options.inspect_only) server_args.push_back("--inspect");
  auto server = Subprocess::Start(server_args, server_spawn);
  if (!server.ok()) return server.status();
  cluster->server_ = std::make_unique<Subprocess>(*std::move(server));
  auto line = cluster->server_->ReadStdoutLine(options.ready_timeout);
  if (!line.ok()) {
    return absl::UnavailableError(absl::StrCat("the server did not start (", line.status().message(),
                                               ")\n", cluster->ServerLogTail()));
  }
  auto address = ParseListeningLine(*line);
  if (!address.ok()) return address.status();
  cluster->address_ = *address;
  // Keep reading the server's stdout so that it can never block on a full pipe.
  const int fd = cluster->server_->stdout_fd();
  cluster->drain_ = std::thread([fd] {
    char buf[4096];
    while (read(fd, buf, sizeof buf) > 0) {
    }
  });
  for (int i = 0; i < options.workers; ++i) {
    SpawnOptions worker_spawn;
    worker_spawn.silence_stdout = true;
    worker_spawn.stderr_path = absl::StrCat(options.log_dir, "/worker-", i, ".log");
    std::vector<std::string> argv = {options.worker_binary, "serve", "--server", cluster->address_,
                                     "--slots", "1", "--name", absl::StrCat("local-", i)};
    argv.insert(argv.end(), options.worker_args.begin(), options.worker_args.end());
    auto worker = Subprocess::Start(argv, worker_spawn);
    if (!worker.ok()) return worker.status();
    cluster->workers_.push_back(*std::move(worker));
  }
  return cluster;
}

LocalCluster::~LocalCluster() { Stop(); }

void LocalCluster::Stop() {
  for (auto& w : workers_) w.Signal(SIGTERM);
  for (auto& w : workers_) w.Stop(kStopGrace);
  workers_.clear();
  if (server_ != nullptr) {
    server_->Stop(kStopGrace);
    if (drain_.joinable()) drain_.join();
    server_.reset();
  }
}

std::string LocalCluster::ServerLogTail() const {
  std::string s = ReadWholeFile(options_.log_dir + "/server.log").value_or("");
  constexpr size_t kTail = 4000;
  if (s.size() > kTail) s = "..." + s.substr(s.size() - kTail);
  return s.empty() ? "" : "server log:\n" + s;
}

}  // namespace mbopt::client
