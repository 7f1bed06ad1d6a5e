// examples/fmu through the service: `mbopt run` starts a server and two
// workers, which open the FMU for every analysis; the same study gives the
// same result with one worker and with two.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "tests/e2e/e2e_harness.h"

namespace mbopt::e2e {
namespace {

std::string Describe(const client::Subprocess::Output& out) {
  return absl::StrCat("exit ", out.exit_code, "\nstdout:\n", out.stdout_text, "\nstderr:\n", out.stderr_text);
}

std::string ReadSource(const std::string& relative) {
  std::ifstream in(std::string(MBOPT_E2E_SOURCE_DIR) + "/" + relative);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The example's study and scene in `dir`, the scene naming this build's FMU
// (the example names it in the default build folder).
std::string WriteExample(const ScratchDir& dir) {
  std::string scene = ReadSource("examples/fmu/oscillator.scene.textproto");
  const std::string relative = "../../build/tests/fmu/archives/damped_oscillator.fmu";
  const std::size_t at = scene.find(relative);
  EXPECT_NE(at, std::string::npos);
  scene.replace(at, relative.size(), std::string(MBOPT_TEST_FMU_DIR) + "/damped_oscillator.fmu");
  dir.Write("oscillator.scene.textproto", scene);
  return dir.Write("oscillator.study.textproto", ReadSource("examples/fmu/oscillator.study.textproto"));
}

TEST(FmuEndToEnd, ExampleStudyConvergesThroughMboptRunWithTheSameResultOnOneAndTwoWorkers) {
  ScratchDir dir;
  const std::string study = WriteExample(dir);
  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()};
  auto two = Mbopt({"run", study, "--workers", "2", "--json", "--discard-db"}, env);
  ASSERT_EQ(two.exit_code, 0) << two.stdout_text << two.stderr_text;
  EXPECT_EQ(JsonField(two.stdout_text, "status"), "converged") << two.stdout_text;
  auto one = Mbopt({"run", study, "--workers", "1", "--json", "--discard-db"}, env);
  ASSERT_EQ(one.exit_code, 0) << one.stdout_text << one.stderr_text;
  EXPECT_EQ(Comparable(one.stdout_text), Comparable(two.stdout_text));
}

// The study carries its FMU: a job killed with its server (SIGKILL after
// the first cycle) resumes from its database alone, with the FMU file gone
// and the scene's path leading nowhere, and ends with the result of a run
// that never stopped, bit for bit.
TEST(FmuEndToEnd, AJobResumesFromItsDatabaseAloneWithTheFmuFileGone) {
  ScratchDir dir;
  const std::string fmu = dir.File("oscillator.fmu");
  std::filesystem::copy_file(std::string(MBOPT_TEST_FMU_DIR) + "/damped_oscillator.fmu", fmu);
  std::string scene = ReadSource("examples/fmu/oscillator.scene.textproto");
  const std::string relative = "../../build/tests/fmu/archives/damped_oscillator.fmu";
  const std::size_t at = scene.find(relative);
  ASSERT_NE(at, std::string::npos);
  scene.replace(at, relative.size(), fmu);
  dir.Write("oscillator.scene.textproto", scene);
  const std::string study = dir.Write("oscillator.study.textproto", ReadSource("examples/fmu/oscillator.study.textproto"));
  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()};
  auto reference = Mbopt({"run", study, "--workers", "2", "--json", "--discard-db"}, env);
  ASSERT_EQ(reference.exit_code, 0) << Describe(reference);

  const std::string db = dir.File("jobs.db");
  auto server = StartServer(db, {"--lease-ms", "1500", "--heartbeat-ms", "200", "--crash-after-cycles", "1"},
                            "127.0.0.1:0", dir.File("server.log"));
  ASSERT_TRUE(server.ok()) << server.status();
  std::vector<client::Subprocess> pool;
  for (int i = 0; i < 2; ++i) pool.push_back(StartWorker(server->address, {}, dir.File(absl::StrCat("w", i, ".log"))));
  auto submitted = Mbopt({"submit", study, "--server", server->address});
  ASSERT_EQ(submitted.exit_code, 0) << Describe(submitted);
  const std::string job = Trim(submitted.stdout_text);
  auto crashed = server->process->Wait(kGuard);
  ASSERT_TRUE(crashed.ok()) << crashed.status();
  EXPECT_EQ(*crashed, 128 + SIGKILL);
  for (auto& w : pool) w.Stop(kGuard);

  std::filesystem::remove(fmu);
  auto resumed = Mbopt({"resume", job, "--db", db, "--workers", "2"}, env);
  ASSERT_EQ(resumed.exit_code, 0) << Describe(resumed);
  auto results = Mbopt({"results", job, "--json", "--db", db}, env);
  ASSERT_EQ(results.exit_code, 0) << Describe(results);
  EXPECT_EQ(JsonField(results.stdout_text, "status"), "converged") << results.stdout_text;
  EXPECT_EQ(Comparable(results.stdout_text), Comparable(reference.stdout_text));
}

}  // namespace
}  // namespace mbopt::e2e
