#include "worker/external/runner.h"

#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <fstream>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "tests/testing/temp_dir.h"

namespace mbopt::external {
namespace {

using ::mbopt::testing::TempDir;

// A driver whose program is the script `script` of `base`, run by /bin/sh,
// reading parameter `a` from its input and writing results.json.
DriverDeclaration ShDriver(const TempDir& base, const std::string& script) {
  base.Write("run.sh", script, /*executable=*/true);
  DriverDeclaration d;
  d.name = "sh-driver";
  d.command = {"/bin/sh", "./run.sh"};
  d.base_directory = base.path();
  d.files = {"run.sh"};
  d.parameters = {"a", "b"};
  d.input_template_text = "a={a}\nb={b}\n";
  d.input_template_source = "in.tmpl";
  d.input_file = "input.sh";
  d.results_file = "results.json";
  d.results_format = ResultsFormat::kJson;
  d.timeout_s = 20.0;
  return d;
}

RunOptions Options(const TempDir& work, const std::string& id) {
  RunOptions options;
  options.analysis_id = id;
  options.work_directory = work.path() / "runs";
  options.kill_grace_s = 0.2;
  return options;
}

const std::map<std::string, double> kValues = {{"a", 0.1}, {"b", -3.0}};

bool Mentions(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(ExternalRunner, RunsTheDriverAndReadsItsJsonResults) {
  TempDir base, work;
  const DriverDeclaration driver = ShDriver(base, R"(. ./input.sh
printf '{"values": {"a": %s, "b": %s}, "series": {"y": [1, 2]}, "time": [0, 0.5]}' "$a" "$b" > results.json
)");
  const auto outcome = RunExternalAnalysis(driver, kValues, Options(work, "a17"));
  ASSERT_TRUE(outcome.ok()) << outcome.status();
  ASSERT_TRUE(outcome->failure.ok()) << outcome->failure.reason;
  // The design's numbers went through the input file and came back bit-identical.
  EXPECT_EQ(outcome->results.values.at("a"), 0.1);
  EXPECT_EQ(outcome->results.values.at("b"), -3.0);
  EXPECT_EQ(outcome->results.series.at("y"), (std::vector<double>{1, 2}));
  EXPECT_EQ(outcome->results.time_s, (std::vector<double>{0, 0.5}));
  EXPECT_EQ(outcome->exit_code, 0);
  EXPECT_EQ(outcome->run_folder, work.path() / "runs" / "a17-sh-driver");
  EXPECT_FALSE(std::filesystem::exists(outcome->run_folder));
  EXPECT_EQ(outcome->cleanup_problem, "");
}

TEST(ExternalRunner, KeepsTheFolderWhenAskedWithOwnerOnlyAccess) {
  TempDir base, work;
  const DriverDeclaration driver = ShDriver(base, "echo out; echo err >&2; echo '{}' > results.json\n");
  RunOptions options = Options(work, "k1");
  options.keep_run_folder = true;
  const auto outcome = RunExternalAnalysis(driver, kValues, options);
  ASSERT_TRUE(outcome.ok()) << outcome.status();
  ASSERT_TRUE(outcome->failure.ok()) << outcome->failure.reason;
  const auto folder = outcome->run_folder;
  ASSERT_TRUE(std::filesystem::is_directory(folder));
  EXPECT_EQ(std::filesystem::status(folder).permissions() & std::filesystem::perms::all, std::filesystem::perms::owner_all);
  std::ifstream input(folder / "input.sh");
  std::string line;
  std::getline(input, line);
  EXPECT_EQ(line, "a=0.10000000000000001");
  EXPECT_TRUE(std::filesystem::exists(folder / "run.sh"));
  EXPECT_TRUE(std::filesystem::exists(folder / "driver.stdout"));
  EXPECT_TRUE(std::filesystem::exists(folder / "driver.stderr"));
  // A second analysis with the same id would reuse the folder: refused.
  const auto again = RunExternalAnalysis(driver, kValues, options);
  EXPECT_EQ(again.status().code(), absl::StatusCode::kFailedPrecondition) << again.status();
}

TEST(ExternalRunner, ExitCodeThreeIsAFailedAnalysisWithTheTailOfStderr) {
  TempDir base, work;
  const DriverDeclaration driver =
      ShDriver(base, "i=1; while [ $i -le 12 ]; do printf 'err-%02d\\n' $i >&2; i=$((i+1)); done; exit 3\n");
  const auto outcome = RunExternalAnalysis(driver, kValues, Options(work, "x3"));
  ASSERT_TRUE(outcome.ok()) << outcome.status();
  EXPECT_EQ(outcome->failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_EQ(outcome->exit_code, 3);
  const std::string& reason = outcome->failure.reason;
  EXPECT_TRUE(Mentions(reason, "driver 'sh-driver' exited with code 3 (success: 0)")) << reason;
  EXPECT_TRUE(Mentions(reason, "err-03\n")) << reason;
  EXPECT_TRUE(Mentions(reason, "err-12")) << reason;
  EXPECT_FALSE(Mentions(reason, "err-02")) << reason;
  EXPECT_FALSE(std::filesystem::exists(outcome->run_folder));
}

TEST(ExternalRunner, AProgramAmongTheFilesRunsFromTheAnalysisFolder) {
  TempDir base, work;
  DriverDeclaration driver = ShDriver(base, R"(#!/bin/sh
. ./input.sh
printf '{"values": {"b": %s}}' "$b" > results.json
)");
  driver.command = {"./run.sh"};
  const auto outcome = RunExternalAnalysis(driver, kValues, Options(work, "p1"));
  ASSERT_TRUE(outcome.ok()) << outcome.status();
  ASSERT_TRUE(outcome->failure.ok()) << outcome->failure.reason;
  EXPECT_EQ(outcome->results.values.at("b"), -3.0);
}

TEST(ExternalRunner, ADriverKilledByASignalIsAFailedAnalysis) {
  TempDir base, work;
  const DriverDeclaration driver = ShDriver(base, "echo 'about to crash' >&2; kill -SEGV $$\n");
  const auto outcome = RunExternalAnalysis(driver, kValues, Options(work, "g1"));
  ASSERT_TRUE(outcome.ok()) << outcome.status();
  EXPECT_EQ(outcome->failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_EQ(outcome->term_signal, SIGSEGV);
  EXPECT_TRUE(Mentions(outcome->failure.reason, "was killed by signal 11")) << outcome->failure.reason;
  EXPECT_TRUE(Mentions(outcome->failure.reason, "about to crash")) << outcome->failure.reason;
}

TEST(ExternalRunner, DeclaredSuccessCodesAreSuccess) {
  TempDir base, work;
  DriverDeclaration driver = ShDriver(base, "echo '{}' > results.json; exit 3\n");
  driver.success_exit_codes = {0, 3};
  const auto outcome = RunExternalAnalysis(driver, kValues, Options(work, "s3"));
  ASSERT_TRUE(outcome.ok()) << outcome.status();
  EXPECT_TRUE(outcome->failure.ok()) << outcome->failure.reason;
}

TEST(ExternalRunner, FailureMarkerInStdoutOrResultsFailsTheAnalysis) {
  TempDir base, work;
  DriverDeclaration driver =
      ShDriver(base, "echo 'solver: SIMULATION FAILED at t=0.3'; echo 'no convergence' >&2; echo '{}' > results.json\n");
  driver.failure_marker = "SIMULATION FAILED";
  auto outcome = RunExternalAnalysis(driver, kValues, Options(work, "m1"));
  ASSERT_TRUE(outcome.ok()) << outcome.status();
  EXPECT_EQ(outcome->failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_TRUE(Mentions(outcome->failure.reason, "\"SIMULATION FAILED\" in driver.stdout")) << outcome->failure.reason;
  EXPECT_TRUE(Mentions(outcome->failure.reason, "no convergence")) << outcome->failure.reason;

  driver = ShDriver(base, "printf '{\"values\": {}}\\nSIMULATION FAILED\\n' > results.json\n");
  driver.failure_marker = "SIMULATION FAILED";
  outcome = RunExternalAnalysis(driver, kValues, Options(work, "m2"));
  ASSERT_TRUE(outcome.ok()) << outcome.status();
  EXPECT_EQ(outcome->failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_TRUE(Mentions(outcome->failure.reason, "\"SIMULATION FAILED\" in results.json")) << outcome->failure.reason;
}

TEST(ExternalRunner, TimeLimitKillsTheWholeProcessGroupEvenAChildIgnoringSigterm) {
  TempDir base, work;
  const std::filesystem::path pid_file = work.path() / "child.pid";
  DriverDeclaration driver = ShDriver(base, R"(
sh -c 'trap "" TERM; echo $$ > "$1.tmp"; mv "$1.tmp" "$1"; exec sleep 1000' child "$1" &
trap '' TERM
while :; do sleep 1; done
)");
  driver.command.push_back(pid_file.string());
  driver.timeout_s = 1.0;
  const auto outcome = RunExternalAnalysis(driver, kValues, Options(work, "t1"));
  ASSERT_TRUE(outcome.ok()) << outcome.status();
  EXPECT_EQ(outcome->failure.kind, spec::FailureKind::kTimeLimit);
  EXPECT_TRUE(Mentions(outcome->failure.reason, "ran past its time limit of 1 s")) << outcome->failure.reason;
  // The limit, the grace period and the kill, with room for a loaded machine.
  EXPECT_GE(outcome->wall_seconds, 1.0);
  EXPECT_LT(outcome->wall_seconds, 10.0);

  std::ifstream in(pid_file);
  pid_t child = 0;
  ASSERT_TRUE(in >> child) << "the driver's child wrote no pid to " << pid_file;
  ASSERT_GT(child, 1);
  errno = 0;
  EXPECT_EQ(kill(child, 0), -1) << "the driver's child " << child << " survived the time limit";
  EXPECT_EQ(errno, ESRCH);
  EXPECT_FALSE(std::filesystem::exists(outcome->run_folder));
}

TEST(ExternalRunner, ABackgroundProcessLeftByASuccessfulDriverIsKilled) {
  TempDir base, work;
  const std::filesystem::path pid_file = work.path() / "left.pid";
  DriverDeclaration driver = ShDriver(base, R"(
sh -c 'echo $$ > "$1.tmp"; mv "$1.tmp" "$1"; exec sleep 1000' left "$1" &
while [ ! -s "$1" ]; do sleep 0.05; done
echo '{}' > results.json
)");
  driver.command.push_back(pid_file.string());
  const auto outcome = RunExternalAnalysis(driver, kValues, Options(work, "b1"));
  ASSERT_TRUE(outcome.ok()) << outcome.status();
  EXPECT_TRUE(outcome->failure.ok()) << outcome->failure.reason;
  std::ifstream in(pid_file);
  pid_t left = 0;
  ASSERT_TRUE(in >> left);
  errno = 0;
  EXPECT_EQ(kill(left, 0), -1) << "process " << left << " outlived its analysis";
  EXPECT_EQ(errno, ESRCH);
}

// True once `pid` is gone or a zombie (an orphan's new parent may be slow
// to reap it, or be this test process, a subreaper since the runs above).
bool Ended(pid_t pid) {
  while (waitpid(pid, nullptr, WNOHANG) > 0) {
  }
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return true;
  const size_t paren = line.rfind(')');
  return paren != std::string::npos && paren + 2 < line.size() && line[paren + 2] == 'Z';
}

// A worker killed outright (SIGKILL: no code of it runs) in the middle of an
// analysis: its guard kills the driver's group, the driver's child that
// ignores SIGTERM included, instead of leaving them running orphaned.
TEST(ExternalRunner, ARunnerKilledWithSigkillLeavesNoDriverProcessRunning) {
  TempDir base, work;
  const std::filesystem::path pid_file = work.path() / "pids";
  DriverDeclaration driver = ShDriver(base, R"(
sh -c 'trap "" TERM; exec sleep 1000' child &
trap '' TERM
echo "$$ $!" > "$1.tmp"; mv "$1.tmp" "$1"
while :; do sleep 1; done
)");
  driver.command.push_back(pid_file.string());
  driver.timeout_s = 600.0;
  const pid_t runner = fork();
  ASSERT_GE(runner, 0);
  if (runner == 0) {
    (void)RunExternalAnalysis(driver, kValues, Options(work, "k9"));
    _exit(0);
  }
  pid_t driver_pid = 0, child_pid = 0;
  for (int i = 0; i < 2000 && !(std::ifstream(pid_file) >> driver_pid >> child_pid); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_GT(child_pid, 1) << "the driver wrote no pids to " << pid_file;
  ASSERT_FALSE(Ended(driver_pid));
  ASSERT_EQ(kill(runner, SIGKILL), 0);
  ASSERT_EQ(waitpid(runner, nullptr, 0), runner);
  bool ended = false;
  for (int i = 0; i < 1000 && !ended; ++i) {  // up to 10 s on a loaded machine
    ended = Ended(driver_pid) && Ended(child_pid);
    if (!ended) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(ended) << "driver " << driver_pid << " or its child " << child_pid << " outlived the killed runner";
  if (!ended) kill(-driver_pid, SIGKILL);
}

TEST(ExternalRunner, MalformedResultsNameFileAndLine) {
  TempDir base, work;
  const DriverDeclaration driver = ShDriver(base, "printf '{\\n  \"values\": {\"a\": 1,}\\n}\\n' > results.json\n");
  const auto outcome = RunExternalAnalysis(driver, kValues, Options(work, "r1"));
  ASSERT_TRUE(outcome.ok()) << outcome.status();
  EXPECT_EQ(outcome->failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_TRUE(Mentions(outcome->failure.reason, "malformed results: results.json:2:")) << outcome->failure.reason;
}

TEST(ExternalRunner, MissingResultsFileIsNamed) {
  TempDir base, work;
  const DriverDeclaration driver = ShDriver(base, "echo 'wrote nothing' >&2\n");
  const auto outcome = RunExternalAnalysis(driver, kValues, Options(work, "r2"));
  ASSERT_TRUE(outcome.ok()) << outcome.status();
  EXPECT_EQ(outcome->failure.kind, spec::FailureKind::kInvalidModel);
  EXPECT_TRUE(Mentions(outcome->failure.reason, "wrote no results file results.json")) << outcome->failure.reason;
  EXPECT_TRUE(Mentions(outcome->failure.reason, "wrote nothing")) << outcome->failure.reason;
}

TEST(ExternalRunner, DakotaResultsWithANanAreANonFiniteValue) {
  TempDir base, work;
  DriverDeclaration driver = ShDriver(base, "printf '1.5 mass\\nnan stress\\n' > results.out\n");
  driver.results_file = "results.out";
  driver.results_format = ResultsFormat::kDakota;
  const auto outcome = RunExternalAnalysis(driver, kValues, Options(work, "d1"));
  ASSERT_TRUE(outcome.ok()) << outcome.status();
  EXPECT_EQ(outcome->failure.kind, spec::FailureKind::kNonFiniteValue);
  EXPECT_TRUE(Mentions(outcome->failure.reason, "values.stress in results.out is not finite")) << outcome->failure.reason;
}

TEST(ExternalRunner, RefusesToCopyALinkLeadingOutside) {
  TempDir outside, base, work;
  outside.Write("secret", "x\n");
  DriverDeclaration driver = ShDriver(base, "echo '{}' > results.json\n");
  std::filesystem::create_symlink(outside.path() / "secret", base.path() / "data");
  driver.files.push_back("data");
  const auto outcome = RunExternalAnalysis(driver, kValues, Options(work, "l1"));
  ASSERT_FALSE(outcome.ok());
  EXPECT_EQ(outcome.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_TRUE(Mentions(std::string(outcome.status().message()), "a link leading outside")) << outcome.status();
  EXPECT_FALSE(std::filesystem::exists(work.path() / "runs" / "l1-sh-driver"));
}

TEST(ExternalRunner, ACommandThatCannotStartIsAnErrorNamingIt) {
  TempDir base, work;
  DriverDeclaration driver = ShDriver(base, "echo '{}' > results.json\n");
  driver.command = {(base.path() / "no-such-program").string()};
  const auto outcome = RunExternalAnalysis(driver, kValues, Options(work, "c1"));
  ASSERT_FALSE(outcome.ok());
  EXPECT_EQ(outcome.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_TRUE(Mentions(std::string(outcome.status().message()), "cannot start " + driver.command[0]))
      << outcome.status();
  EXPECT_FALSE(std::filesystem::exists(work.path() / "runs" / "c1-sh-driver"));
}

TEST(ExternalRunner, RefusesValuesThatDoNotMatchTheParameters) {
  TempDir base, work;
  const DriverDeclaration driver = ShDriver(base, "echo '{}' > results.json\n");
  auto outcome = RunExternalAnalysis(driver, {{"a", 1.0}}, Options(work, "v1"));
  EXPECT_EQ(outcome.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(Mentions(std::string(outcome.status().message()), "no value for parameter(s) b")) << outcome.status();
  outcome = RunExternalAnalysis(driver, {{"a", 1.0}, {"b", 2.0}, {"c", 3.0}}, Options(work, "v2"));
  EXPECT_EQ(outcome.status().code(), absl::StatusCode::kInvalidArgument);
  outcome = RunExternalAnalysis(driver, {{"a", 1.0}, {"b", std::nan("")}}, Options(work, "v3"));
  EXPECT_EQ(outcome.status().code(), absl::StatusCode::kInvalidArgument);
  outcome = RunExternalAnalysis(driver, kValues, Options(work, "../up"));
  EXPECT_EQ(outcome.status().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace mbopt::external
