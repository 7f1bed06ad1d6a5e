// The secure set-up as deploy/README.md gives it, with real processes on
// loopback: `mbopt-server init-tls`, a server with --tls-dir, a worker and
// the CLI with the CA and their tokens. Also what each program says, and
// which exit code it gives, when the CA or the token is missing or wrong.
#include <signal.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "client/exit_codes.h"
#include "client/subprocess.h"
#include "tests/e2e/e2e_harness.h"

namespace mbopt::e2e {
namespace {

using client::kExitBadInput;
using client::kExitDenied;
using client::kExitOk;
using client::kExitUnreachable;
using client::Subprocess;
using ::testing::HasSubstr;
using ::testing::Not;

std::string Describe(const Subprocess::Output& out) {
  return absl::StrCat("exit ", out.exit_code, "\nstdout:\n", out.stdout_text, "\nstderr:\n", out.stderr_text);
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

unsigned Mode(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) return 0;
  return info.st_mode & 0777;
}

int Lines(const std::string& text) { return static_cast<int>(std::count(text.begin(), text.end(), '\n')); }

// A worker run to its exit (it is expected to stop on its own).
Subprocess::Output RunWorker(const std::vector<std::string>& args, const std::vector<std::string>& env = {}) {
  std::vector<std::string> argv = {WorkerBinary(), "serve"};
  argv.insert(argv.end(), args.begin(), args.end());
  absl::StatusOr<Subprocess::Output> out = client::RunCommand(argv, kGuard, env);
  if (!out.ok()) return Subprocess::Output{-1, "", std::string(out.status().message())};
  return *out;
}

TEST(Secure, InitTlsServerWorkerAndClientRunAJobWithTokens) {
  ScratchDir dir;
  const std::string pki = dir.File("pki");
  absl::StatusOr<Subprocess::Output> made = client::RunCommand(
      {ServerBinary(), "init-tls", pki, "--host", "localhost", "--host", "127.0.0.1", "--user", "alice"}, kGuard);
  ASSERT_TRUE(made.ok()) << made.status();
  ASSERT_EQ(made->exit_code, 0) << Describe(*made);
  EXPECT_THAT(made->stdout_text, HasSubstr("--tls-dir " ));
  for (const char* secret : {"ca.key", "server.key", "worker.key", "worker.token", "admin.token", "alice.token", "tokens"}) {
    EXPECT_EQ(Mode(pki + "/" + secret), 0600u) << secret;
  }
  EXPECT_EQ(Mode(pki), 0700u);
  // Never over an existing installation.
  absl::StatusOr<Subprocess::Output> again = client::RunCommand({ServerBinary(), "init-tls", pki}, kGuard);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->exit_code, 1);
  EXPECT_THAT(again->stderr_text, HasSubstr("exists already; not overwritten"));

  auto server = StartServer(dir.File("jobs.db"), {"--tls-dir", pki}, "127.0.0.1:0", dir.File("server.log"));
  ASSERT_TRUE(server.ok()) << server.status();
  const std::string addr = server->address;
  Subprocess worker = StartWorker(addr, {"--tls-ca", pki + "/ca.pem", "--token-file", pki + "/worker.token"},
                                  dir.File("worker.log"));
  const std::vector<std::string> alice = {"MBOPT_TLS_CA=" + pki + "/ca.pem", "MBOPT_TOKEN_FILE=" + pki + "/alice.token"};

  auto submitted = Mbopt({"submit", VehicleStudy(), "--watch", "--server", addr}, alice);
  ASSERT_EQ(submitted.exit_code, kExitOk) << Describe(submitted);
  // The first line is the job's id: random on a server with tokens, so that
  // it says nothing of how many jobs exist.
  const std::string job = submitted.stdout_text.substr(0, submitted.stdout_text.find('\n'));
  EXPECT_EQ(job.size(), 16u) << job;
  EXPECT_EQ(job.rfind("job-", 0), 0u) << job;
  EXPECT_EQ(job.find_first_not_of("0123456789abcdef", 4), std::string::npos) << job;
  auto secure = Mbopt({"results", job, "--json", "--server", addr}, alice);
  ASSERT_EQ(secure.exit_code, kExitOk) << Describe(secure);
  // The same result as the private server of `mbopt run`, which has neither
  // TLS nor tokens; the settings in the environment do not reach it.
  auto plain = Mbopt({"run", VehicleStudy(), "--json", "--workers", "1", "--discard-db"}, alice);
  ASSERT_EQ(plain.exit_code, kExitOk) << Describe(plain);
  for (const char* key : {"status", "cycles", "analyses", "objective", "max_violation"}) {
    EXPECT_EQ(JsonField(secure.stdout_text, key), JsonField(plain.stdout_text, key)) << key;
  }
  EXPECT_THAT(secure.stdout_text, HasSubstr("\"design\""));

  // Options instead of the environment; the admin sees the job.
  auto listed = Mbopt({"list", "--server", addr, "--tls-ca", pki + "/ca.pem", "--token-file", pki + "/admin.token"});
  EXPECT_EQ(listed.exit_code, kExitOk) << Describe(listed);
  EXPECT_THAT(listed.stdout_text, HasSubstr(job));
  EXPECT_THAT(listed.stdout_text, HasSubstr(" alice\n")) << "the OWNER column";

  // Refusals: one line each, with the exit code that says which.
  auto no_token = Mbopt({"list", "--server", addr, "--tls-ca", pki + "/ca.pem"});
  EXPECT_EQ(no_token.exit_code, kExitDenied) << Describe(no_token);
  EXPECT_THAT(no_token.stderr_text, HasSubstr("needs a token"));
  EXPECT_EQ(Lines(no_token.stderr_text), 1) << no_token.stderr_text;
  const std::string wrong_token_file = dir.Write("wrong.token", "mbopt_00000000\n");
  // A token others can read is refused by the CLI and the worker before
  // any call.
  std::filesystem::permissions(wrong_token_file, std::filesystem::perms::owner_read |
                                                     std::filesystem::perms::owner_write |
                                                     std::filesystem::perms::group_read |
                                                     std::filesystem::perms::others_read);
  auto readable_token = Mbopt({"status", job, "--server", addr, "--tls-ca", pki + "/ca.pem", "--token-file",
                               wrong_token_file});
  EXPECT_EQ(readable_token.exit_code, kExitBadInput) << Describe(readable_token);
  EXPECT_THAT(readable_token.stderr_text, HasSubstr("has mode 0644: readable by every user of this machine"));
  auto readable_token_worker = RunWorker({"--server", addr, "--tls-ca", pki + "/ca.pem", "--token-file",
                                          wrong_token_file});
  EXPECT_NE(readable_token_worker.exit_code, 0) << Describe(readable_token_worker);
  EXPECT_THAT(readable_token_worker.stderr_text, HasSubstr("chmod 600 " + wrong_token_file));
  std::filesystem::permissions(wrong_token_file, std::filesystem::perms::owner_read |
                                                     std::filesystem::perms::owner_write);
  auto wrong_token = Mbopt({"status", job, "--server", addr, "--tls-ca", pki + "/ca.pem", "--token-file",
                            wrong_token_file});
  EXPECT_EQ(wrong_token.exit_code, kExitDenied) << Describe(wrong_token);
  EXPECT_THAT(wrong_token.stderr_text, HasSubstr("not one this server accepts"));
  auto worker_as_user = Mbopt({"list", "--server", addr, "--tls-ca", pki + "/ca.pem", "--token-file",
                               pki + "/worker.token"});
  EXPECT_EQ(worker_as_user.exit_code, kExitDenied) << Describe(worker_as_user);
  auto no_ca = Mbopt({"list", "--server", addr, "--token-file", pki + "/admin.token"});
  EXPECT_EQ(no_ca.exit_code, kExitUnreachable) << Describe(no_ca);
  EXPECT_THAT(no_ca.stderr_text, HasSubstr("speaks TLS: give its CA certificate with --tls-ca"));
  EXPECT_EQ(Lines(no_ca.stderr_text), 1) << no_ca.stderr_text;
  auto missing_ca = Mbopt({"list", "--server", addr, "--tls-ca", dir.File("none.pem")});
  EXPECT_EQ(missing_ca.exit_code, kExitBadInput) << Describe(missing_ca);
  EXPECT_THAT(missing_ca.stderr_text, HasSubstr("--tls-ca: cannot read"));

  // Workers with a user's token, or without the CA, stop at once and say why.
  auto user_worker = RunWorker({"--server", addr, "--tls-ca", pki + "/ca.pem", "--token-file", pki + "/alice.token"});
  EXPECT_EQ(user_worker.exit_code, 3) << Describe(user_worker);
  EXPECT_THAT(user_worker.stderr_text, HasSubstr("refused this worker: a user token cannot act as a worker"));
  auto plaintext_worker = RunWorker({"--server", addr}, {"MBOPT_TOKEN_FILE=" + pki + "/worker.token"});
  EXPECT_EQ(plaintext_worker.exit_code, 3) << Describe(plaintext_worker);
  EXPECT_THAT(plaintext_worker.stderr_text, HasSubstr("speaks TLS"));

  // A token added to the table works once the server has read it again
  // (SIGHUP); until then it is refused.
  absl::StatusOr<Subprocess::Output> added = client::RunCommand(
      {ServerBinary(), "add-token", "--tokens", pki + "/tokens", "--role", "user", "--name", "bob", "--out",
       pki + "/bob.token"},
      kGuard);
  ASSERT_TRUE(added.ok());
  ASSERT_EQ(added->exit_code, 0) << Describe(*added);
  EXPECT_EQ(Mode(pki + "/bob.token"), 0600u);
  const std::vector<std::string> bob = {"MBOPT_TLS_CA=" + pki + "/ca.pem", "MBOPT_TOKEN_FILE=" + pki + "/bob.token"};
  EXPECT_EQ(Mbopt({"list", "--server", addr}, bob).exit_code, kExitDenied);
  server->process->Signal(SIGHUP);
  Subprocess::Output bobs_list;
  const auto deadline = std::chrono::steady_clock::now() + kGuard;
  do {
    bobs_list = Mbopt({"list", "--server", addr}, bob);
  } while (bobs_list.exit_code == kExitDenied && std::chrono::steady_clock::now() < deadline);
  EXPECT_EQ(bobs_list.exit_code, kExitOk) << Describe(bobs_list);
  EXPECT_THAT(bobs_list.stdout_text, Not(HasSubstr(job))) << "Bob sees only his own jobs";
  // Alice's job is answered to Bob as one that does not exist.
  auto bob_reads_alices = Mbopt({"status", job, "--server", addr}, bob);
  auto bob_reads_none = Mbopt({"status", "job-99", "--server", addr}, bob);
  EXPECT_EQ(bob_reads_alices.exit_code, kExitBadInput) << Describe(bob_reads_alices);
  EXPECT_EQ(bob_reads_none.exit_code, kExitBadInput) << Describe(bob_reads_none);
  EXPECT_THAT(bob_reads_alices.stderr_text, HasSubstr("no job with id '" + job + "'"));
  EXPECT_THAT(bob_reads_none.stderr_text, HasSubstr("no job with id 'job-99'"));

  EXPECT_EQ(worker.Stop(kGuard), 0);
  EXPECT_EQ(server->process->Stop(kGuard), 0);
  // The plain-text attempts above are one readable line each in the
  // server's log, without OpenSSL's words (those come with GRPC_VERBOSITY).
  const std::string server_log = ReadFile(dir.File("server.log"));
  EXPECT_THAT(server_log, HasSubstr("mbopt-server: refused a connection: the client does not speak TLS"));
  EXPECT_THAT(server_log, Not(HasSubstr("ssl_transport_security"))) << server_log;

  // A renewed certificate, from the same CA: clients keep their ca.pem.
  absl::StatusOr<Subprocess::Output> renewed =
      client::RunCommand({ServerBinary(), "renew-cert", pki, "--days", "10"}, kGuard);
  ASSERT_TRUE(renewed.ok());
  ASSERT_EQ(renewed->exit_code, 0) << Describe(*renewed);
  EXPECT_THAT(renewed->stdout_text, HasSubstr("for localhost, 127.0.0.1"));
  EXPECT_NE(ReadFile(pki + "/server.pem"), ReadFile(pki + "/server.pem.old"));
  EXPECT_EQ(Mode(pki + "/server.key"), 0600u);
  auto restarted = StartServer(dir.File("jobs.db"), {"--tls-dir", pki}, "127.0.0.1:0", dir.File("server2.log"));
  ASSERT_TRUE(restarted.ok()) << restarted.status();
  auto after_renewal = Mbopt({"status", job, "--server", restarted->address}, alice);
  EXPECT_EQ(after_renewal.exit_code, kExitOk) << Describe(after_renewal);
  EXPECT_EQ(restarted->process->Stop(kGuard), 0);
  // It expires within 30 days: the server says so at every start.
  EXPECT_THAT(ReadFile(dir.File("server2.log")), HasSubstr("WARNING: the server certificate"));
  // No token ever reaches a log or an output.
  const std::string logs = ReadFile(dir.File("server.log")) + ReadFile(dir.File("worker.log")) +
                           submitted.stdout_text + submitted.stderr_text + user_worker.stderr_text;
  for (const char* file : {"alice.token", "admin.token", "worker.token"}) {
    std::string token = ReadFile(pki + "/" + file);
    token.pop_back();
    EXPECT_THAT(logs, Not(HasSubstr(token))) << file;
  }
}

TEST(Secure, ServerRefusesAnAddressOtherMachinesReachWithoutTlsAndTokens) {
  ScratchDir dir;
  // Refused before it listens: nothing is opened off loopback.
  absl::StatusOr<Subprocess::Output> refused = client::RunCommand(
      {ServerBinary(), "--listen", "0.0.0.0:0", "--db", dir.File("jobs.db")}, kGuard);
  ASSERT_TRUE(refused.ok());
  EXPECT_EQ(refused->exit_code, 1);
  EXPECT_THAT(refused->stderr_text, HasSubstr("neither TLS nor tokens"));
  EXPECT_THAT(refused->stderr_text, HasSubstr("--tls-dir DIR"));
  EXPECT_EQ(Lines(refused->stderr_text), 1) << refused->stderr_text;
}

}  // namespace
}  // namespace mbopt::e2e
