// End-to-end tests with real processes on loopback: mbopt-server,
// mbopt-worker and the mbopt CLI, on the vehicle example (a full
// optimization takes a few seconds). What "the same result" means: the
// `results --json` document without job id and wall time, compared as text;
// its numbers are printed with 17 significant digits, so equal text is
// bit-identical doubles.
#include <signal.h>
#include <sys/stat.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <google/protobuf/text_format.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "mbopt/v1/service.grpc.pb.h"
#include "spec/io/study_io.h"
#include "tests/e2e/e2e_harness.h"
#include "tests/fuzz/mutate.h"
#include "tests/spec/oscillator_scene.h"

namespace mbopt::e2e {
namespace {

using client::Subprocess;

constexpr int kExitOk = 0, kExitNotConverged = 1, kExitBadInput = 2, kExitUnreachable = 3;
constexpr int kKilledBySigkill = 128 + SIGKILL;
// Short leases so that a lost worker's task is handed out again quickly.
const std::vector<std::string> kFastLeases = {"--lease-ms", "1500", "--heartbeat-ms", "200"};

// A job ended in a state that is an outcome of the optimization (not a crash
// of the service): the exit codes of watch/results for it.
bool IsOutcomeExitCode(int code) { return code == kExitOk || code == kExitNotConverged; }

std::string Describe(const Subprocess::Output& out) {
  return absl::StrCat("exit ", out.exit_code, "\nstdout:\n", out.stdout_text, "\nstderr:\n",
                      out.stderr_text);
}

// Submits a study (default: the vehicle), follows it to its end and returns
// `results --json`.
std::string SubmitWatchAndGetResults(const std::string& address, const std::string& study = VehicleStudy()) {
  auto submitted = Mbopt({"submit", study, "--server", address});
  EXPECT_EQ(submitted.exit_code, kExitOk) << Describe(submitted);
  const std::string job = Trim(submitted.stdout_text);
  auto watched = Mbopt({"watch", job, "--server", address});
  EXPECT_TRUE(IsOutcomeExitCode(watched.exit_code)) << Describe(watched);
  auto results = Mbopt({"results", job, "--json", "--server", address});
  EXPECT_TRUE(IsOutcomeExitCode(results.exit_code)) << Describe(results);
  return results.stdout_text;
}

// `mbopt workers` lists `count` workers or more (polled with a deadline as
// a failure guard: registration has no event a client could wait for).
std::string WorkersWhenRegistered(const std::string& address, size_t count) {
  const auto deadline = std::chrono::steady_clock::now() + kGuard;
  while (true) {
    auto listed = Mbopt({"workers", "--server", address});
    EXPECT_EQ(listed.exit_code, kExitOk) << Describe(listed);
    size_t rows = 0;
    for (char c : listed.stdout_text) rows += c == '\n';
    if (rows >= count + 1 || std::chrono::steady_clock::now() > deadline || listed.exit_code != kExitOk) {
      return listed.stdout_text;
    }
  }
}

// A study (default: the vehicle) on a fresh server with `workers` workers
// started with `worker_args`.
std::string ReferenceResult(int workers, const std::string& study = VehicleStudy(),
                            const std::vector<std::string>& worker_args = {}) {
  ScratchDir dir;
  auto server = StartServer(dir.File("ref.db"), {}, "127.0.0.1:0", dir.File("server.log"));
  EXPECT_TRUE(server.ok()) << server.status();
  if (!server.ok()) return "";
  std::vector<Subprocess> pool;
  for (int i = 0; i < workers; ++i) pool.push_back(StartWorker(server->address, worker_args));
  // A study naming a driver is refused until a worker declaring it has registered.
  if (!worker_args.empty()) WorkersWhenRegistered(server->address, static_cast<size_t>(workers));
  std::string json = SubmitWatchAndGetResults(server->address, study);
  for (auto& w : pool) w.Stop(kGuard);
  EXPECT_EQ(server->process->Stop(kGuard), 0) << "server did not shut down cleanly";
  return json;
}

// The "cycles:" line of `mbopt status`.
int CyclesInStatus(const std::string& status_text) {
  const std::string key = "cycles:";
  auto pos = status_text.find(key);
  return pos == std::string::npos ? -1 : std::atoi(status_text.c_str() + pos + key.size());
}

void ExpectConsecutiveHistory(const std::string& json) {
  std::vector<int> cycles = HistoryCycles(json);
  ASSERT_FALSE(cycles.empty()) << json;
  for (size_t i = 0; i < cycles.size(); ++i) {
    EXPECT_EQ(cycles[i], static_cast<int>(i) + 1) << "history entry " << i << " in\n" << json;
  }
}

TEST(EndToEnd, SubmitWatchAndResultsOnLoopbackWithTwoWorkers) {
  ScratchDir dir;
  auto server = StartServer(dir.File("jobs.db"), {}, "127.0.0.1:0", dir.File("server.log"));
  ASSERT_TRUE(server.ok()) << server.status();
  std::vector<Subprocess> pool;
  for (int i = 0; i < 2; ++i) {
    pool.push_back(StartWorker(server->address, {"--name", absl::StrCat("w", i)},
                               dir.File(absl::StrCat("worker", i, ".log"))));
  }
  const std::string addr = server->address;

  auto submitted = Mbopt({"submit", VehicleStudy(), "--server", addr});
  ASSERT_EQ(submitted.exit_code, kExitOk) << Describe(submitted);
  const std::string job = Trim(submitted.stdout_text);
  ASSERT_FALSE(job.empty());
  EXPECT_EQ(job.find('\n'), std::string::npos) << "submit prints only the job id";

  auto watched = Mbopt({"watch", job, "--server", addr});
  ASSERT_TRUE(IsOutcomeExitCode(watched.exit_code)) << Describe(watched);
  EXPECT_NE(watched.stdout_text.find("cycle"), std::string::npos) << watched.stdout_text;
  EXPECT_NE(watched.stdout_text.find("maxfout"), std::string::npos) << watched.stdout_text;
  EXPECT_NE(watched.stdout_text.find(job + ": "), std::string::npos) << watched.stdout_text;
  EXPECT_EQ(watched.stdout_text.find("\033["), std::string::npos)
      << "no terminal control sequences when stdout is not a terminal";

  auto results = Mbopt({"results", job, "--json", "--server", addr});
  ASSERT_EQ(results.exit_code, watched.exit_code) << Describe(results);
  const std::string& json = results.stdout_text;
  for (const char* key : {"status", "cycles", "analyses", "objective", "objective_unit",
                          "max_violation", "design", "wall_seconds", "history"}) {
    EXPECT_NE(json.find(absl::StrCat("\"", key, "\":")), std::string::npos) << key << "\n" << json;
  }
  const std::string status = JsonField(json, "status");
  EXPECT_TRUE(status == "converged" || status == "max_cycles" || status == "stalled") << json;
  EXPECT_EQ(watched.exit_code, status == "converged" ? kExitOk : kExitNotConverged);
  EXPECT_GT(std::stoi(JsonField(json, "cycles")), 0);
  EXPECT_GT(std::stoll(JsonField(json, "analyses")), 0);
  ExpectConsecutiveHistory(json);

  auto csv = Mbopt({"results", job, "--csv", "--server", addr});
  EXPECT_EQ(csv.stdout_text.rfind("cycle,attempt,accepted,objective", 0), 0u) << csv.stdout_text;
  auto table = Mbopt({"results", job, "--server", addr});
  EXPECT_NE(table.stdout_text.find("status:        " + status), std::string::npos)
      << table.stdout_text;
  auto st = Mbopt({"status", job, "--server", addr});
  EXPECT_EQ(st.exit_code, kExitOk) << Describe(st);
  EXPECT_NE(st.stdout_text.find(job), std::string::npos);
  auto listed = Mbopt({"list", "--server", addr});
  EXPECT_EQ(listed.exit_code, kExitOk) << Describe(listed);
  EXPECT_NE(listed.stdout_text.find(job), std::string::npos) << listed.stdout_text;
  auto from_env = Mbopt({"status", job}, {"MBOPT_SERVER=" + addr});
  EXPECT_EQ(from_env.exit_code, kExitOk) << "MBOPT_SERVER selects the server\n"
                                         << Describe(from_env);

  auto submit_watch = Mbopt({"submit", VehicleStudy(), "--watch", "--server", addr});
  EXPECT_EQ(submit_watch.exit_code, watched.exit_code) << Describe(submit_watch);
  EXPECT_NE(submit_watch.stdout_text.find("maxfout"), std::string::npos) << submit_watch.stdout_text;

  for (auto& w : pool) EXPECT_EQ(w.Stop(kGuard), 0) << "workers exit cleanly on SIGTERM";
  EXPECT_EQ(server->process->Stop(kGuard), 0);
}

TEST(EndToEnd, ResultsAreIdenticalWithOneTwoAndFourWorkers) {
  const std::string one = Comparable(ReferenceResult(1));
  ASSERT_FALSE(one.empty());
  EXPECT_EQ(Comparable(ReferenceResult(2)), one);
  EXPECT_EQ(Comparable(ReferenceResult(4)), one);
}

// Runs the vehicle on a server started with `server_args` and a worker that
// kills itself (SIGKILL) holding its third task, then a survivor; checks
// that the job ends with the result of an undisturbed run and returns the
// job's status text.
std::string RunWithAWorkerKilledMidCycle(const std::vector<std::string>& server_args,
                                         const std::string& study = VehicleStudy(),
                                         const std::vector<std::string>& worker_args = {}) {
  const std::string reference = Comparable(ReferenceResult(1, study, worker_args));
  EXPECT_FALSE(reference.empty());
  ScratchDir dir;
  auto server = StartServer(dir.File("jobs.db"), server_args, "127.0.0.1:0", dir.File("server.log"));
  EXPECT_TRUE(server.ok()) << server.status();
  if (!server.ok()) return "";
  // The doomed worker takes tasks alone first, so that it surely receives its
  // third task while the first cycle's batch is in progress.
  std::vector<std::string> doomed_args = {"--die-after-tasks", "3", "--name", "doomed"};
  doomed_args.insert(doomed_args.end(), worker_args.begin(), worker_args.end());
  Subprocess doomed = StartWorker(server->address, doomed_args, dir.File("doomed.log"));
  if (!worker_args.empty()) WorkersWhenRegistered(server->address, 1);
  auto submitted = Mbopt({"submit", study, "--server", server->address});
  EXPECT_EQ(submitted.exit_code, kExitOk) << Describe(submitted);
  const std::string job = Trim(submitted.stdout_text);
  auto died = doomed.Wait(kGuard);
  EXPECT_TRUE(died.ok()) << died.status();
  if (died.ok()) {
    EXPECT_EQ(*died, kKilledBySigkill);
  }
  std::vector<std::string> survivor_args = {"--name", "survivor"};
  survivor_args.insert(survivor_args.end(), worker_args.begin(), worker_args.end());
  Subprocess survivor = StartWorker(server->address, survivor_args, dir.File("survivor.log"));

  auto watched = Mbopt({"watch", job, "--server", server->address});
  EXPECT_TRUE(IsOutcomeExitCode(watched.exit_code)) << Describe(watched);
  auto results = Mbopt({"results", job, "--json", "--server", server->address});
  EXPECT_EQ(Comparable(results.stdout_text), reference);
  auto status = Mbopt({"status", job, "--server", server->address});
  survivor.Stop(kGuard);
  EXPECT_EQ(server->process->Stop(kGuard), 0);
  return status.stdout_text;
}

TEST(EndToEnd, WorkerKilledMidCycleDoesNotChangeTheResult) { RunWithAWorkerKilledMidCycle(kFastLeases); }

// With a lease far longer than the job, only the closed connection can
// tell the server that the worker died: its task must be handed out again
// at once (docs/workers.md, "A worker that dies").
TEST(EndToEnd, KilledWorkersTaskIsRequeuedWithoutWaitingForItsLease) {
  constexpr int kLongLeaseMs = 300'000;
  const std::string status = RunWithAWorkerKilledMidCycle({"--lease-ms", std::to_string(kLongLeaseMs)});
  // The job's own clock: a lost lease would have added 300 s.
  const size_t at = status.find("wall time:");
  ASSERT_NE(at, std::string::npos) << status;
  EXPECT_LT(std::stod(status.substr(at + 10)), 0.2 * kLongLeaseMs / 1000.0) << status;
}

// Runs `study` with 2 workers on a server that kills itself where
// `crash_args` says (by default after its second cycle commit), restarts it
// on the same database and port, and checks that the resumed job ends with
// the uninterrupted run's result, bit for bit.
void ExpectServerKilledMidJobResumesBitIdentically(
    const std::string& study, const std::vector<std::string>& server_args = {},
    const std::vector<std::string>& crash_flags = {"--crash-after-cycles", "2"}, int min_cycles_at_restart = 2,
    const std::vector<std::string>& worker_args = {}) {
  const std::string reference = Comparable(ReferenceResult(2, study, worker_args));
  ASSERT_FALSE(reference.empty());

  ScratchDir dir;
  const std::string db = dir.File("jobs.db");
  std::vector<std::string> crash_args = kFastLeases;
  crash_args.insert(crash_args.end(), server_args.begin(), server_args.end());
  crash_args.insert(crash_args.end(), crash_flags.begin(), crash_flags.end());
  auto first = StartServer(db, crash_args, "127.0.0.1:0", dir.File("server1.log"));
  ASSERT_TRUE(first.ok()) << first.status();
  std::vector<Subprocess> pool;
  for (int i = 0; i < 2; ++i) {
    pool.push_back(StartWorker(first->address, worker_args, dir.File(absl::StrCat("worker", i, ".log"))));
  }
  if (!worker_args.empty()) WorkersWhenRegistered(first->address, pool.size());
  auto submitted = Mbopt({"submit", study, "--server", first->address});
  ASSERT_EQ(submitted.exit_code, kExitOk) << Describe(submitted);
  const std::string job = Trim(submitted.stdout_text);
  auto crashed = first->process->Wait(kGuard);
  ASSERT_TRUE(crashed.ok()) << crashed.status();
  ASSERT_EQ(*crashed, kKilledBySigkill) << crash_flags[0] << " kills the server";

  // Same database, same port: the running workers reconnect by themselves.
  std::vector<std::string> restart_args = kFastLeases;
  restart_args.insert(restart_args.end(), server_args.begin(), server_args.end());
  auto second = StartServer(db, restart_args, absl::StrCat("127.0.0.1:", first->port),
                            dir.File("server2.log"));
  ASSERT_TRUE(second.ok()) << second.status();
  auto st = Mbopt({"status", job, "--server", second->address});
  ASSERT_EQ(st.exit_code, kExitOk) << Describe(st);
  if (st.stdout_text.find("interrupted") != std::string::npos) {
    auto resumed = Mbopt({"resume", job, "--server", second->address});
    ASSERT_EQ(resumed.exit_code, kExitOk) << Describe(resumed);
  }
  auto watched = Mbopt({"watch", job, "--server", second->address});
  ASSERT_TRUE(IsOutcomeExitCode(watched.exit_code)) << Describe(watched);
  auto results = Mbopt({"results", job, "--json", "--server", second->address});
  ExpectConsecutiveHistory(results.stdout_text);
  // The crash really was in the middle of the job.
  const int cycles_at_restart = CyclesInStatus(st.stdout_text);
  EXPECT_GE(cycles_at_restart, min_cycles_at_restart) << st.stdout_text;
  EXPECT_LT(cycles_at_restart, std::stoi(JsonField(results.stdout_text, "cycles")));
  EXPECT_EQ(Comparable(results.stdout_text), reference);
  for (auto& w : pool) EXPECT_EQ(w.Stop(kGuard), 0);
  EXPECT_EQ(second->process->Stop(kGuard), 0);
}

TEST(EndToEnd, ServerKilledMidJobResumesBitIdentically) {
  ExpectServerKilledMidJobResumesBitIdentically(VehicleStudy());
}

// Killed inside a transaction of results (their rows written, COMMIT not
// reached): none of them is in the log after the restart, the optimizer asks
// for them again, and the result is unchanged.
TEST(EndToEnd, ServerKilledInTheMiddleOfAGroupCommitResumesBitIdentically) {
  ExpectServerKilledMidJobResumesBitIdentically(VehicleStudy(), {}, {"--crash-in-commit", "8"}, 1);
}

// Without a sync per commit a crash of the process still loses nothing
// committed (the operating system holds the WAL's pages).
TEST(EndToEnd, ServerKilledMidJobResumesBitIdenticallyWithNormalDurability) {
  ExpectServerKilledMidJobResumesBitIdentically(VehicleStudy(), {"--durability", "normal"});
}

// A database whose server died: `status --db` says so and how to go on,
// `watch --db` and `list --db` end at once, and none of them resumes the
// job (nothing would analyse it); `resume --db` then finishes it with the
// uninterrupted run's result.
void ExpectStatusOfADeadServersDatabaseAndResume(const std::string& study,
                                                 const std::vector<std::string>& worker_args = {}) {
  const std::string reference = Comparable(ReferenceResult(2, study, worker_args));
  ScratchDir dir;
  const std::string db = dir.File("jobs.db");
  std::vector<std::string> crash_args = kFastLeases;
  crash_args.insert(crash_args.end(), {"--crash-after-cycles", "2"});
  auto server = StartServer(db, crash_args, "127.0.0.1:0", dir.File("server.log"));
  ASSERT_TRUE(server.ok()) << server.status();
  std::vector<Subprocess> pool;
  for (int i = 0; i < 2; ++i) {
    pool.push_back(StartWorker(server->address, worker_args, dir.File(absl::StrCat("w", i, ".log"))));
  }
  if (!worker_args.empty()) WorkersWhenRegistered(server->address, pool.size());
  auto submitted = Mbopt({"submit", study, "--server", server->address});
  ASSERT_EQ(submitted.exit_code, kExitOk) << Describe(submitted);
  const std::string job = Trim(submitted.stdout_text);
  auto crashed = server->process->Wait(kGuard);
  ASSERT_TRUE(crashed.ok()) << crashed.status();
  ASSERT_EQ(*crashed, kKilledBySigkill);
  for (auto& w : pool) w.Stop(kGuard);
  // At the default level a worker logs one line per batch of results.
  std::ifstream worker_log(dir.File("w0.log"));
  std::stringstream worker_text;
  worker_text << worker_log.rdbuf();
  EXPECT_NE(worker_text.str().find(absl::StrCat(job, ": ")), std::string::npos) << worker_text.str();
  EXPECT_NE(worker_text.str().find(" delivered ("), std::string::npos) << worker_text.str();

  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()};
  for (int look = 0; look < 2; ++look) {  // the second look finds the same: the first changed nothing
    auto status = Mbopt({"status", job, "--db", db}, env);
    ASSERT_EQ(status.exit_code, kExitOk) << Describe(status);
    EXPECT_NE(status.stdout_text.find("status:        interrupted"), std::string::npos) << status.stdout_text;
    EXPECT_NE(status.stdout_text.find("server not running"), std::string::npos) << status.stdout_text;
    EXPECT_NE(status.stdout_text.find(absl::StrCat("mbopt resume ", job, " --db ", db)), std::string::npos)
        << status.stdout_text;
    EXPECT_EQ(CyclesInStatus(status.stdout_text), 2) << status.stdout_text;
    EXPECT_EQ(status.stdout_text.find("--drivers FILE") != std::string::npos, !worker_args.empty())
        << status.stdout_text;
  }
  auto listed = Mbopt({"list", "--db", db}, env);
  ASSERT_EQ(listed.exit_code, kExitOk) << Describe(listed);
  EXPECT_NE(listed.stdout_text.find("interrupted"), std::string::npos) << listed.stdout_text;
  auto watched = Mbopt({"watch", job, "--db", db}, env);
  EXPECT_EQ(watched.exit_code, kExitNotConverged) << Describe(watched);

  std::vector<std::string> resume = {"resume", job, "--db", db, "--workers", "2"};
  resume.insert(resume.end(), worker_args.begin(), worker_args.end());
  auto resumed = Mbopt(resume, env);
  ASSERT_EQ(resumed.exit_code, kExitOk) << Describe(resumed);
  auto results = Mbopt({"results", job, "--json", "--db", db}, env);
  ASSERT_EQ(results.exit_code, kExitOk) << Describe(results);
  EXPECT_EQ(Comparable(results.stdout_text), reference);
}

TEST(EndToEnd, StatusOfADatabaseWhoseServerDiedSaysInterruptedAndResumeFinishesIt) {
  ExpectStatusOfADeadServersDatabaseAndResume(VehicleStudy());
}

// The same for an external simulator's job: the status names the driver
// the resume needs, and `resume --db --drivers FILE` starts workers that
// declare it.
TEST(EndToEnd, ExternalJobOfADeadServerResumesWithDbAndDrivers) {
  ExpectStatusOfADeadServersDatabaseAndResume(ExternalStudy(), {"--drivers", ExternalDrivers()});
}

// ---------------------------------------------------- simulator gradients --

// The report's optimum of the vehicle problem (section 4.1, Table 2): peak
// seat acceleration 6.40 m/s^2 after 12 cycles.
constexpr double kReportVehicleObjective = 6.40;

// `mbopt run` with 2 workers on the vehicle with simulator sensitivities:
// the report's optimum, with one analysis per cycle (plus rejected trials)
// where forward differences spend at least 1 + n = 7.
TEST(EndToEnd, SimulatorSensitivitiesReachTheReportsOptimumWithFewerAnalyses) {
  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(),
                                        "MBOPT_WORKER_BIN=" + WorkerBinary()};
  auto sensitivity = Mbopt({"run", VehicleSensitivityStudy(), "--workers", "2", "--json"}, env);
  ASSERT_EQ(sensitivity.exit_code, kExitOk) << Describe(sensitivity);
  auto finite_differences = Mbopt({"run", VehicleStudy(), "--workers", "2", "--json"}, env);
  ASSERT_EQ(finite_differences.exit_code, kExitOk) << Describe(finite_differences);
  const std::string& json = sensitivity.stdout_text;
  EXPECT_EQ(JsonField(json, "status"), "converged") << json;
  EXPECT_LE(std::stod(JsonField(json, "objective")), kReportVehicleObjective) << json;
  EXPECT_LE(std::stod(JsonField(json, "max_violation")), 0.0) << json;
  ExpectConsecutiveHistory(json);
  const long long analyses = std::stoll(JsonField(json, "analyses"));
  const long long fd_analyses = std::stoll(JsonField(finite_differences.stdout_text, "analyses"));
  const int cycles = std::stoi(JsonField(json, "cycles"));
  const int fd_cycles = std::stoi(JsonField(finite_differences.stdout_text, "cycles"));
  std::cout << "simulator: " << cycles << " cycles, " << analyses << " analyses, F = "
            << JsonField(json, "objective") << "; finite differences: " << fd_cycles << " cycles, "
            << fd_analyses << " analyses, F = " << JsonField(finite_differences.stdout_text, "objective")
            << "\n";
  // Per cycle: forward differences at least 1 + n = 7 analyses, the
  // simulator 1 (the accepted trial's gradients start the next cycle).
  EXPECT_LE(analyses, 1 + 2LL * cycles) << "at most one rejected trial per cycle on average";
  EXPECT_GE(fd_analyses, 7LL * fd_cycles);
  EXPECT_LT(3 * analyses, fd_analyses) << "far fewer analyses than forward differences";
}

TEST(EndToEnd, SimulatorSensitivityJobKilledMidJobResumesBitIdentically) {
  ExpectServerKilledMidJobResumesBitIdentically(VehicleSensitivityStudy());
}

TEST(EndToEnd, RunJsonStartsEverythingAndPrintsOneJsonObject) {
  const std::string reference = Comparable(ReferenceResult(2));
  auto run = Mbopt({"run", VehicleStudy(), "--workers", "2", "--json"},
                   {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()});
  ASSERT_TRUE(IsOutcomeExitCode(run.exit_code)) << Describe(run);
  const std::string json = Trim(run.stdout_text);
  ASSERT_FALSE(json.empty());
  EXPECT_EQ(json.front(), '{');
  EXPECT_EQ(json.back(), '}');
  EXPECT_EQ(json.find("\n}"), json.size() - 2) << "exactly one object on stdout";
  EXPECT_EQ(Comparable(run.stdout_text), reference);
  const std::string database = JsonField(json, "database");
  EXPECT_NE(database.find("/mbopt/runs/vehicle-"), std::string::npos) << "where the job is kept\n" << json;
}

// A simulator mbopt did not write (examples/external: a python3 script
// behind a declared driver) optimized through the service: `mbopt run
// --drivers` with two local workers gives the same result, bit for bit, as
// submit and watch to a server with two workers started with --drivers, and
// the optimum sits on the travel limit.
TEST(EndToEnd, ExternalSimulatorStudyRunsThroughRunAndSubmitAlike) {
  const std::string reference = Comparable(ReferenceResult(2, ExternalStudy(), {"--drivers", ExternalDrivers()}));
  ASSERT_FALSE(reference.empty());
  auto run = Mbopt({"run", ExternalStudy(), "--workers", "2", "--drivers", ExternalDrivers(), "--json",
                    "--discard-db"},
                   {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()});
  ASSERT_EQ(run.exit_code, kExitOk) << Describe(run);
  EXPECT_EQ(Comparable(run.stdout_text), reference);
  EXPECT_EQ(JsonField(run.stdout_text, "status"), "converged") << run.stdout_text;
  const double max_violation = std::stod(JsonField(run.stdout_text, "max_violation"));
  EXPECT_LE(max_violation, 0.0) << "the reported design meets the travel limit";
  EXPECT_GT(max_violation, -1e-3) << "and the limit is active at the optimum";
}

// A worker of the external study killed (SIGKILL) as it receives a task,
// in the middle of a cycle: a worker declaring the same driver takes the
// task over and the job ends with the undisturbed run's result, bit for bit.
TEST(EndToEnd, ExternalSimulatorWorkerKilledMidCycleDoesNotChangeTheResult) {
  RunWithAWorkerKilledMidCycle(kFastLeases, ExternalStudy(), {"--drivers", ExternalDrivers()});
}

// A server killed in the middle of the external study resumes it with the
// uninterrupted run's result, bit for bit: the driver is deterministic and
// its numbers are parsed exactly.
TEST(EndToEnd, ExternalSimulatorJobKilledMidJobResumesBitIdentically) {
  ExpectServerKilledMidJobResumesBitIdentically(ExternalStudy(), {}, {"--crash-after-cycles", "2"}, 2,
                                                {"--drivers", ExternalDrivers()});
}

// Workers say what they can run: a study naming a driver no registered
// worker declares is refused at submit, naming what the workers do declare;
// once a worker declares it, the job runs, and only on that worker.
TEST(EndToEnd, ExternalStudyIsRefusedWithoutItsDriverAndRunsOnlyWhereDeclared) {
  ScratchDir dir;
  auto server = StartServer(dir.File("jobs.db"), {}, "127.0.0.1:0", dir.File("server.log"));
  ASSERT_TRUE(server.ok()) << server.status();
  Subprocess plain = StartWorker(server->address, {"--name", "plain"}, dir.File("plain.log"));
  WorkersWhenRegistered(server->address, 1);
  auto refused = Mbopt({"submit", ExternalStudy(), "--server", server->address});
  EXPECT_EQ(refused.exit_code, kExitBadInput) << Describe(refused);
  EXPECT_NE(refused.stderr_text.find("no registered worker declares driver \"quarter_car\"; the registered "
                                     "workers declare no drivers"),
            std::string::npos)
      << Describe(refused);

  Subprocess able = StartWorker(server->address, {"--name", "able", "--drivers", ExternalDrivers()},
                                dir.File("able.log"));
  const std::string listed = WorkersWhenRegistered(server->address, 2);
  EXPECT_NE(listed.find("driver quarter_car"), std::string::npos) << listed;
  auto submitted = Mbopt({"submit", ExternalStudy(), "--server", server->address});
  ASSERT_EQ(submitted.exit_code, kExitOk) << Describe(submitted);
  const std::string job = Trim(submitted.stdout_text);
  auto watched = Mbopt({"watch", job, "--server", server->address});
  EXPECT_EQ(watched.exit_code, kExitOk) << Describe(watched);
  auto after = Mbopt({"workers", "--server", server->address});
  // Every analysis ran on the worker that declares the driver; none was
  // handed to the other and back.
  std::istringstream rows(after.stdout_text);
  std::string line;
  int checked = 0;
  while (std::getline(rows, line)) {
    std::istringstream fields(line);
    std::string id, name, token;
    long long slots = 0, analyses = -1;
    fields >> id >> name >> token >> slots >> analyses;
    if (name == "plain") {
      EXPECT_EQ(analyses, 0) << after.stdout_text;
    }
    if (name == "able") {
      EXPECT_GT(analyses, 0) << after.stdout_text;
    }
    checked += name == "plain" || name == "able";
  }
  EXPECT_EQ(checked, 2) << after.stdout_text;
  EXPECT_EQ(plain.Stop(kGuard), 0);
  EXPECT_EQ(able.Stop(kGuard), 0);
  EXPECT_EQ(server->process->Stop(kGuard), 0);
}

// A drivers file with a problem stops `mbopt run` before anything starts,
// naming the file, the line and the field.
TEST(BadInput, RunWithABadDriversFileNamesItsProblem) {
  ScratchDir dir;
  const std::string drivers = dir.Write("bad.drivers.textproto", "driver {\n  name: \"x\"\n  timeout_s: -1\n}\n");
  auto run = Mbopt({"run", ExternalStudy(), "--drivers", drivers, "--discard-db"},
                   {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()});
  EXPECT_EQ(run.exit_code, kExitBadInput) << Describe(run);
  EXPECT_NE(run.stderr_text.find("bad.drivers.textproto:"), std::string::npos) << Describe(run);
  EXPECT_NE(run.stderr_text.find("driver[0]."), std::string::npos) << Describe(run);
  EXPECT_EQ(run.stdout_text.find("server at"), std::string::npos) << "nothing was started";
}

// From `mbopt run` to the report page in two commands: run keeps its
// database (0600) and prints where, and report, results and status read it
// with --db, without a server started by hand.
TEST(EndToEnd, RunKeepsItsDatabaseForReportAndResults) {
  ScratchDir state;
  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary(),
                                        "XDG_STATE_HOME=" + state.path()};
  auto run = Mbopt({"run", VehicleStudy(), "--workers", "2"}, env);
  ASSERT_EQ(run.exit_code, kExitOk) << Describe(run);
  const size_t at = run.stdout_text.find("database:");
  ASSERT_NE(at, std::string::npos) << Describe(run);
  const std::string db = Trim(run.stdout_text.substr(at + 9, run.stdout_text.find('\n', at) - at - 9));
  EXPECT_EQ(db.rfind(state.path() + "/mbopt/runs/vehicle-", 0), 0u) << db;
  struct stat st {};
  ASSERT_EQ(stat(db.c_str(), &st), 0) << db;
  EXPECT_EQ(st.st_mode & 0777, 0600u) << "a job database is for its owner only";

  ScratchDir out;
  const std::string page = out.File("vehicle.html");
  auto report = Mbopt({"report", "job-1", "--db", db, "-o", page}, env);
  ASSERT_EQ(report.exit_code, kExitOk) << Describe(report);
  std::ifstream html(page);
  std::stringstream text;
  text << html.rdbuf();
  EXPECT_NE(text.str().find("6.389"), std::string::npos) << "the page shows the optimum";
  // And the responses there: the seat acceleration and every travel limit,
  // analysed again at the initial and the final design.
  for (const char* expected : {"Responses at the initial and final designs", "objective: max_abs of seat_acceleration",
                               "s1: max_abs of s1 &lt;= 0.456 in", "s5: max_abs of s5 &lt;= 1 in", "final design"}) {
    EXPECT_NE(text.str().find(expected), std::string::npos) << expected;
  }
  int plots = 0;
  for (size_t at = text.str().find("<svg"); at != std::string::npos; at = text.str().find("<svg", at + 1)) ++plots;
  EXPECT_EQ(plots, 5 + 6 + 1)
      << "five history plots, the objective's output and five constraints, the vehicle's schematic";
  EXPECT_NE(text.str().find("<h2>Mechanism</h2>"), std::string::npos);
  EXPECT_NE(text.str().find(">initial design</text>"), std::string::npos) << "both designs drawn";
  EXPECT_NE(text.str().find(">final design</text>"), std::string::npos) << "both designs drawn";
  auto results = Mbopt({"results", "job-1", "--json", "--db", db}, env);
  ASSERT_EQ(results.exit_code, kExitOk) << Describe(results);
  EXPECT_EQ(Comparable(results.stdout_text), Comparable(ReferenceResult(2)));
  EXPECT_EQ(Mbopt({"status", "job-1", "--db", out.File("missing.db")}, env).exit_code, kExitBadInput);
  EXPECT_EQ(Mbopt({"status", "job-1", "--db", db, "--server", "127.0.0.1:1"}, env).exit_code, kExitBadInput);

  auto discarded = Mbopt({"run", VehicleStudy(), "--workers", "1", "--discard-db"}, env);
  ASSERT_EQ(discarded.exit_code, kExitOk) << Describe(discarded);
  EXPECT_EQ(discarded.stdout_text.find("database:"), std::string::npos) << Describe(discarded);
}

// `mbopt draw` writes a scene's animated drawing without a server: one
// frame per instant of the press's grid, at a design set on the command
// line; a scene kind without geometry and an unknown name are bad input.
TEST(Draw, WritesTheAnimatedDrawingOfASceneOrAStudy) {
  ScratchDir out;
  const std::vector<std::string> env = {"MBOPT_WORKER_BIN=" + WorkerBinary()};
  const std::string examples = std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/";
  const std::string page = out.File("press.html");
  auto drawn = Mbopt({"draw", examples + "press/press.scene.textproto", "-o", page}, env);
  ASSERT_EQ(drawn.exit_code, kExitOk) << Describe(drawn);
  EXPECT_NE(drawn.stdout_text.find("(101 instants)"), std::string::npos) << Describe(drawn);
  std::stringstream text;
  text << std::ifstream(page).rdbuf();
  int frames = 0;
  for (size_t at = text.str().find("<g class=\"frame\""); at != std::string::npos;
       at = text.str().find("<g class=\"frame\"", at + 1)) {
    ++frames;
  }
  EXPECT_EQ(frames, 101);
  EXPECT_NE(text.str().find("<input type=\"range\""), std::string::npos);
  EXPECT_EQ(text.str().find("http"), std::string::npos) << "nothing fetched";

  // A study's scene at a design of the command line: the longer rod moves
  // the slider's start from r + l = 0.95 m to 1.15 m.
  const std::string longer = out.File("longer.html");
  auto set = Mbopt({"draw", examples + "press/press.study.textproto", "--set", "rod_length=1", "-o", longer}, env);
  ASSERT_EQ(set.exit_code, kExitOk) << Describe(set);
  std::stringstream longer_text;
  longer_text << std::ifstream(longer).rdbuf();
  EXPECT_NE(longer_text.str(), text.str());

  auto external = Mbopt({"draw", examples + "external/quarter_car.scene.textproto", "-o", out.File("q.html")}, env);
  EXPECT_EQ(external.exit_code, kExitBadInput) << Describe(external);
  EXPECT_NE(external.stderr_text.find("only multibody, linkage and lumped scenes can be drawn"), std::string::npos)
      << Describe(external);
  auto unknown = Mbopt({"draw", examples + "press/press.scene.textproto", "--set", "no_such=1"}, env);
  EXPECT_EQ(unknown.exit_code, kExitBadInput) << Describe(unknown);
  EXPECT_NE(unknown.stderr_text.find("\"no_such\" is neither a design variable"), std::string::npos)
      << Describe(unknown);
}

// mbopt-server gc prunes finished jobs, exports them readable by --db, never
// gives a pruned id again, and refuses a database a server is using.
TEST(EndToEnd, GcPrunesFinishedJobsAndExportsThemReadably) {
  ScratchDir dir;
  const std::string db = dir.File("jobs.db"), archive = dir.File("archive.db");
  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()};
  std::string first_result;
  {
    auto server = StartServer(db, {}, "127.0.0.1:0", dir.File("server.log"));
    ASSERT_TRUE(server.ok()) << server.status();
    Subprocess worker = StartWorker(server->address);
    first_result = SubmitWatchAndGetResults(server->address);
    SubmitWatchAndGetResults(server->address);
    SubmitWatchAndGetResults(server->address);
    auto busy = client::RunCommand({ServerBinary(), "gc", "--db", db, "--keep", "0"}, kGuard);
    ASSERT_TRUE(busy.ok()) << busy.status();
    EXPECT_EQ(busy->exit_code, 1) << busy->stdout_text << busy->stderr_text;
    EXPECT_NE(busy->stderr_text.find("in use"), std::string::npos) << busy->stderr_text;
    worker.Stop(kGuard);
    EXPECT_EQ(server->process->Stop(kGuard), 0);
  }
  auto usage = client::RunCommand({ServerBinary(), "gc", "--db", db}, kGuard);
  ASSERT_TRUE(usage.ok());
  EXPECT_EQ(usage->exit_code, 2) << "which jobs must be said";
  auto gc = client::RunCommand({ServerBinary(), "gc", "--db", db, "--keep", "1", "--export", archive}, kGuard);
  ASSERT_TRUE(gc.ok()) << gc.status();
  ASSERT_EQ(gc->exit_code, 0) << gc->stdout_text << gc->stderr_text;
  EXPECT_NE(gc->stdout_text.find("pruned 2 of 3 jobs (job-1 .. job-2)"), std::string::npos) << gc->stdout_text;

  auto kept = Mbopt({"list", "--db", db}, env);
  ASSERT_EQ(kept.exit_code, kExitOk) << Describe(kept);
  EXPECT_EQ(kept.stdout_text.find("job-1 "), std::string::npos) << kept.stdout_text;
  EXPECT_NE(kept.stdout_text.find("job-3"), std::string::npos) << kept.stdout_text;
  auto exported = Mbopt({"results", "job-1", "--json", "--db", archive}, env);
  ASSERT_EQ(exported.exit_code, kExitOk) << Describe(exported);
  EXPECT_EQ(Comparable(exported.stdout_text), Comparable(first_result)) << "the archive holds the job bit for bit";
  auto again = client::RunCommand({ServerBinary(), "gc", "--db", db, "--keep", "0", "--dry-run"}, kGuard);
  ASSERT_TRUE(again.ok());
  EXPECT_NE(again->stdout_text.find("would prune 1 of 1 jobs"), std::string::npos) << again->stdout_text;
}

TEST(EndToEnd, ValidatePrintsTheLayoutWithoutAServer) {
  auto out = Mbopt({"validate", VehicleStudy()});
  ASSERT_EQ(out.exit_code, kExitOk) << Describe(out);
  for (const char* expected : {"variables:   6", "x1", "k1", "objective:", "constraints:", "rows", "valid"}) {
    EXPECT_NE(out.stdout_text.find(expected), std::string::npos) << expected << "\n" << out.stdout_text;
  }
  ScratchDir dir;
  const std::string path = dir.Write("broken.study.textproto", "name: \"broken\"\nvariables {\n  lower: 1.0\n");
  auto bad = Mbopt({"validate", path});
  EXPECT_EQ(bad.exit_code, kExitBadInput) << Describe(bad);
  EXPECT_NE(bad.stderr_text.find("broken.study.textproto:"), std::string::npos) << bad.stderr_text;
}

// The study language's newer forms through the whole service: named
// responses with a min-max over two terms (vehicle_worst_case) and two load
// cases analysed at every design point (vehicle_two_roads). Each converges,
// gives the same result bit for bit with one and with two workers, and
// reaches the optimum NLopt's SLSQP finds on the same analyses
// (`mbopt_compare --study FILE`: 1.62335 and 6.44211 m/s^2) within 0.1 %,
// or a better one (the worst case: 1.61893).
TEST(EndToEnd, ResponsesAndLoadCasesRunThroughTheService) {
  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()};
  const std::string examples = std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/vehicle/";
  for (const auto& [file, slsqp] : {std::pair{"vehicle_worst_case.study.textproto", 1.62335},
                                    std::pair{"vehicle_two_roads.study.textproto", 6.44211}}) {
    const std::string study = examples + file;
    auto validate = Mbopt({"validate", study});
    ASSERT_EQ(validate.exit_code, kExitOk) << Describe(validate);
    auto one = Mbopt({"run", study, "--workers", "1", "--json"}, env);
    auto two = Mbopt({"run", study, "--workers", "2", "--json"}, env);
    ASSERT_EQ(two.exit_code, kExitOk) << Describe(two);
    EXPECT_EQ(JsonField(two.stdout_text, "status"), "converged") << file;
    EXPECT_EQ(Comparable(one.stdout_text), Comparable(two.stdout_text)) << file;
    const double objective = std::stod(JsonField(two.stdout_text, "objective"));
    EXPECT_LT(objective, slsqp * (1 + 1e-3)) << file;
    // Lower than a peer's local optimum by more than a percent would be a
    // wrong value, not a better design.
    EXPECT_GT(objective, slsqp * (1 - 1e-2)) << file;
  }
  auto validate = Mbopt({"validate", examples + "vehicle_two_roads.study.textproto"});
  EXPECT_NE(validate.stdout_text.find("load cases:  2"), std::string::npos) << validate.stdout_text;
  EXPECT_NE(validate.stdout_text.find("fast.s1"), std::string::npos) << validate.stdout_text;
  validate = Mbopt({"validate", examples + "vehicle_worst_case.study.textproto"});
  EXPECT_NE(validate.stdout_text.find("axle_springs = k2 + k3"), std::string::npos) << validate.stdout_text;
}

// A maximized objective is reported as the value itself everywhere a client
// sees it (run's summary, every cycle of results, eval), while the optimizer
// minimizes its negative: maximize 3 - (u - 1)^2 - (v + 2)^2, 3 at (1, -2).
TEST(EndToEnd, MaximizedObjectiveIsReportedAsItself) {
  ScratchDir dir;
  dir.Write("carrier.scene.textproto", ::mbopt::testing::CarrierScene());
  const std::string study = dir.Write("hill.study.textproto", ::mbopt::testing::kHillStudy);
  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()};
  auto run = Mbopt({"run", study, "--workers", "2", "--json"}, env);
  ASSERT_EQ(run.exit_code, kExitOk) << Describe(run);
  EXPECT_EQ(JsonField(run.stdout_text, "status"), "converged");
  EXPECT_NEAR(std::stod(JsonField(run.stdout_text, "objective")), 3.0, 1e-6) << run.stdout_text;
  // Every cycle's F is the value (from 3 - 0.25 - 16 = -13.25 at the start),
  // rising to 3: the history's objectives go up, never the negatives down.
  std::vector<double> history;
  const std::string key = "\"objective\": ";
  for (size_t at = run.stdout_text.find("\"history\""); at != std::string::npos;) {
    at = run.stdout_text.find(key, at + 1);
    if (at != std::string::npos) history.push_back(std::stod(run.stdout_text.substr(at + key.size())));
  }
  ASSERT_GE(history.size(), 3u) << run.stdout_text;
  EXPECT_LT(history.front(), -1.0);
  EXPECT_NEAR(history.back(), 3.0, 1e-6);
  auto validate = Mbopt({"validate", study});
  EXPECT_NE(validate.stdout_text.find("maximize the final of hill"), std::string::npos) << validate.stdout_text;
}

// ------------------------------------------------------------- bad input --

TEST(BadInput, MalformedStudyFileNamesFileAndLine) {
  ScratchDir dir;
  const std::string path = dir.Write("broken.study.textproto",
                                     "name: \"broken\"\nvariables {\n  name: \"x1\"\n  lower: 1.0\n");
  auto out = Mbopt({"submit", path, "--server", "127.0.0.1:1"});
  EXPECT_EQ(out.exit_code, kExitBadInput) << Describe(out);
  EXPECT_NE(out.stderr_text.find("broken.study.textproto:"), std::string::npos) << out.stderr_text;
}

// The vehicle study with its scene inlined, as text (a self-contained file).
std::string InlinedVehicleStudy(v1::Study* study) {
  auto read = spec::io::ReadStudyProto(VehicleStudy());
  EXPECT_TRUE(read.ok()) << read.status();
  if (!read.ok()) return "";
  *study = *read;
  std::string text;
  google::protobuf::TextFormat::PrintToString(*study, &text);
  return text;
}

// One validation path: `mbopt validate` (the client's check before submit
// and run) and `mbopt-worker eval` refuse the same hostile files with the
// same message, and neither hangs or crashes.
TEST(BadInput, ValidateAndWorkerEvalAgreeOnHostileFiles) {
  ScratchDir dir;
  v1::Study study;
  const std::string text = InlinedVehicleStudy(&study);
  ASSERT_FALSE(text.empty());
  const std::string zero_scene =
      dir.Write("zero.study.textproto", "name: \"z\"\nscene_file: \"/dev/zero\"\n");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"grid", text + "analysis { time_grid_points: 10000000 }\n"},
      {"memory", text + "analysis { time_grid_points: 1000000 }\n"},
      {"move_limit", text + "optimizer { initial_move_limit: 1e300 }\n"},
      {"nan_screening", text + "optimizer { screening_threshold: nan }\n"},
      {"cycles", text + "optimizer { max_cycles: 2147483647 }\n"},
  };
  std::vector<std::string> paths = {zero_scene};
  for (const auto& [name, body] : cases) paths.push_back(dir.Write(name + ".study.textproto", body));
  for (const std::string& path : paths) {
    auto validated = Mbopt({"validate", path});
    EXPECT_EQ(validated.exit_code, kExitBadInput) << Describe(validated);
    auto evaluated = client::RunCommand({WorkerBinary(), "eval", path}, kGuard);
    ASSERT_TRUE(evaluated.ok()) << evaluated.status();
    EXPECT_NE(evaluated->exit_code, 0) << path;
    const std::string prefix = "mbopt: ";
    ASSERT_EQ(validated.stderr_text.rfind(prefix, 0), 0u) << validated.stderr_text;
    EXPECT_NE(evaluated->stderr_text.find(Trim(validated.stderr_text.substr(prefix.size()))), std::string::npos)
        << "validate: " << validated.stderr_text << "eval: " << evaluated->stderr_text;
  }
}

// The property of tests/fuzz between the programs themselves: a mutated
// example is refused by `mbopt validate` exactly when `mbopt-worker eval`
// refuses it as bad input, with the same message. An accepted mutant may
// take long to analyse (its values pushed to extremes): eval still running
// after a few seconds has accepted it.
TEST(BadInput, MutatedExamplesAgreeBetweenValidateAndWorkerEval) {
  ScratchDir dir;
  v1::Study study;
  const std::string text = InlinedVehicleStudy(&study);
  ASSERT_FALSE(text.empty());
  int refused = 0, accepted = 0, index = 0;
  for (const std::string& mutant : fuzz::MutateStudyText(text, 30, 2026)) {
    const std::string path = dir.Write(absl::StrCat("m", index++, ".study.textproto"), mutant);
    auto validated = Mbopt({"validate", path});
    ASSERT_TRUE(validated.exit_code == kExitOk || validated.exit_code == kExitBadInput) << Describe(validated);
    auto evaluated = client::RunCommand({WorkerBinary(), "eval", path}, std::chrono::seconds(3));
    if (validated.exit_code == kExitBadInput) {
      ++refused;
      ASSERT_TRUE(evaluated.ok()) << path << ": eval went on with a file validate refused\n" << validated.stderr_text;
      EXPECT_EQ(evaluated->exit_code, kExitBadInput) << path;
      const std::string message = Trim(validated.stderr_text.substr(std::string("mbopt: ").size()));
      EXPECT_NE(evaluated->stderr_text.find(message), std::string::npos)
          << "validate: " << validated.stderr_text << "eval: " << evaluated->stderr_text;
    } else {
      ++accepted;
      if (evaluated.ok()) {
        EXPECT_NE(evaluated->exit_code, kExitBadInput) << path << ": validate accepted it\n" << evaluated->stderr_text;
      }
    }
  }
  EXPECT_GT(refused, 0);
  EXPECT_GT(accepted, 0);
}

// The vehicle study on 20,001 instants, written to `dir`: results of about
// 0.19 MB of packed values (1.9 MB unpacked). "" if the example is missing.
std::string FineVehicleStudy(ScratchDir& dir) {
  v1::Study study;
  const std::string text = InlinedVehicleStudy(&study);
  if (text.empty()) return "";
  return dir.Write("fine.study.textproto", text + "analysis { time_grid_points: 20001 }\n");
}

// A result over the message limit goes in pieces: with 64 KiB messages and
// results of about 0.19 MB (20,001 instants, packed), the job ends exactly as
// with the default limits.
TEST(LargeResults, OverTheMessageLimitTheyGoInPiecesAndTheResultIsTheSame) {
  ScratchDir dir;
  const std::string path = FineVehicleStudy(dir);
  ASSERT_FALSE(path.empty());
  auto server = StartServer(dir.File("jobs.db"), {"--max-message-mb", "0.0625"}, "127.0.0.1:0", dir.File("server.log"));
  ASSERT_TRUE(server.ok()) << server.status();
  Subprocess worker = StartWorker(server->address);
  const std::string in_pieces = Comparable(SubmitWatchAndGetResults(server->address, path));
  worker.Stop(kGuard);
  EXPECT_EQ(server->process->Stop(kGuard), 0);
  EXPECT_NE(in_pieces.find("\"status\": \"converged\""), std::string::npos) << in_pieces;
  EXPECT_EQ(in_pieces, Comparable(ReferenceResult(1, path)));
}

// A result larger than the server takes fails its analysis at once, naming
// both sizes (before: refused by gRPC on every try, the job stalled for three
// leases and failed with "lease expired").
TEST(BadInput, ResultOverTheServersLimitIsANamedFailure) {
  ScratchDir dir;
  const std::string path = FineVehicleStudy(dir);
  ASSERT_FALSE(path.empty());
  auto server = StartServer(dir.File("jobs.db"), {"--max-message-mb", "0.0625", "--max-result-mb", "0.125"},
                            "127.0.0.1:0", dir.File("server.log"));
  ASSERT_TRUE(server.ok()) << server.status();
  Subprocess worker = StartWorker(server->address);
  auto submitted = Mbopt({"submit", path, "--watch", "--server", server->address});
  constexpr int kExitJobFailed = 4;
  EXPECT_EQ(submitted.exit_code, kExitJobFailed) << Describe(submitted);
  auto results = Mbopt({"results", "job-1", "--server", server->address});
  EXPECT_NE(results.stdout_text.find("more than the server takes (0.1 MB, mbopt-server --max-result-mb)"),
            std::string::npos)
      << Describe(results);
  worker.Stop(kGuard);
  EXPECT_EQ(server->process->Stop(kGuard), 0);
}

TEST(BadInput, UnknownFieldIsNamed) {
  ScratchDir dir;
  v1::Study study;
  const std::string text = InlinedVehicleStudy(&study);
  ASSERT_FALSE(text.empty());
  const std::string path = dir.Write("unknown.study.textproto", text + "bogus_setting: 3\n");
  auto out = Mbopt({"submit", path, "--server", "127.0.0.1:1"});
  EXPECT_EQ(out.exit_code, kExitBadInput) << Describe(out);
  EXPECT_NE(out.stderr_text.find("bogus_setting"), std::string::npos) << out.stderr_text;
  EXPECT_NE(out.stderr_text.find("unknown.study.textproto"), std::string::npos) << out.stderr_text;
  auto run = Mbopt({"run", path}, {"MBOPT_SERVER_BIN=" + ServerBinary()});
  EXPECT_EQ(run.exit_code, kExitBadInput) << "run checks the file before starting anything\n"
                                          << Describe(run);
}

TEST(BadInput, ReversedBoundsAreNamed) {
  ScratchDir dir;
  v1::Study study;
  ASSERT_FALSE(InlinedVehicleStudy(&study).empty());
  ASSERT_GT(study.variables_size(), 0);
  auto* v = study.mutable_variables(0);
  const double lower = v->lower();
  v->set_lower(v->upper());
  v->set_upper(lower);
  std::string text;
  google::protobuf::TextFormat::PrintToString(study, &text);
  const std::string path = dir.Write("reversed.study.textproto", text);
  auto out = Mbopt({"submit", path, "--server", "127.0.0.1:1"});
  EXPECT_EQ(out.exit_code, kExitBadInput) << Describe(out);
  EXPECT_NE(out.stderr_text.find("reversed.study.textproto"), std::string::npos) << out.stderr_text;
  EXPECT_TRUE(out.stderr_text.find("lower") != std::string::npos ||
              out.stderr_text.find("upper") != std::string::npos)
      << out.stderr_text;
}

TEST(BadInput, UnknownJobIdIsAClearError) {
  ScratchDir dir;
  auto server = StartServer(dir.File("jobs.db"), {}, "127.0.0.1:0", dir.File("server.log"));
  ASSERT_TRUE(server.ok()) << server.status();
  for (const char* command : {"status", "watch", "results", "cancel", "resume"}) {
    auto out = Mbopt({command, "no-such-job", "--server", server->address});
    EXPECT_EQ(out.exit_code, kExitBadInput) << command << "\n" << Describe(out);
    EXPECT_NE(out.stderr_text.find("no-such-job"), std::string::npos)
        << command << "\n" << out.stderr_text;
  }
  EXPECT_EQ(server->process->Stop(kGuard), 0);
}

TEST(BadInput, UnreachableServerIsAClearError) {
  auto out = Mbopt({"list", "--server", "127.0.0.1:1"});
  EXPECT_EQ(out.exit_code, kExitUnreachable) << Describe(out);
  EXPECT_NE(out.stderr_text.find("cannot reach server at 127.0.0.1:1"), std::string::npos)
      << out.stderr_text;
}

TEST(BadInput, UsageErrorsExitWithTwo) {
  EXPECT_EQ(Mbopt({}).exit_code, kExitBadInput);
  EXPECT_EQ(Mbopt({"frobnicate"}).exit_code, kExitBadInput);
  EXPECT_EQ(Mbopt({"status"}).exit_code, kExitBadInput);
  EXPECT_EQ(Mbopt({"run", VehicleStudy(), "--workers", "zero"}).exit_code, kExitBadInput);
  EXPECT_EQ(Mbopt({"results", "j", "--csv", "--json"}).exit_code, kExitBadInput);
}

// Every command of `mbopt` answers --help with its own usage (exit 0, on
// stdout, nothing contacted), and the three programs answer --version with
// the release, the commit they were built from and the schema versions.
TEST(Cli, EveryCommandHasItsHelpAndEveryProgramItsVersion) {
  for (const char* command : {"run", "validate", "draw", "submit", "watch", "status", "list", "workers", "cancel",
                              "resume", "results", "report"}) {
    // The help wins over missing arguments and an unreachable server.
    auto help = Mbopt({command, "--server", "127.0.0.1:1", "--help"});
    EXPECT_EQ(help.exit_code, kExitOk) << command << ": " << Describe(help);
    EXPECT_EQ(help.stdout_text.rfind(std::string("usage: mbopt ") + command + " ", 0), 0u)
        << command << ": " << help.stdout_text;
    EXPECT_NE(help.stdout_text.find("docs/cli.md"), std::string::npos) << command;
    const bool talks_to_server =
        std::string(command) != "run" && std::string(command) != "validate" && std::string(command) != "draw";
    EXPECT_EQ(help.stdout_text.find("--token-file") != std::string::npos, talks_to_server) << command;
  }
  auto short_help = Mbopt({"status", "-h"});
  EXPECT_EQ(short_help.exit_code, kExitOk);
  EXPECT_EQ(short_help.stdout_text.rfind("usage: mbopt status JOB", 0), 0u) << short_help.stdout_text;

  for (const std::string& program : {MboptBinary(), ServerBinary(), WorkerBinary()}) {
    auto version = client::RunCommand({program, "--version"}, kGuard);
    ASSERT_TRUE(version.ok()) << version.status();
    EXPECT_EQ(version->exit_code, 0) << program;
    const std::string name = program.substr(program.rfind('/') + 1);
    // "NAME 0.1.0 (commit <hash or unknown>)"
    EXPECT_EQ(version->stdout_text.rfind(name + " " + MBOPT_TEST_RELEASE + " (commit ", 0), 0u)
        << version->stdout_text;
    const size_t commit = version->stdout_text.find("(commit ") + 8;
    EXPECT_GE(version->stdout_text.find(')', commit) - commit, 7u) << version->stdout_text;
    EXPECT_NE(version->stdout_text.find("mbopt.v1"), std::string::npos) << version->stdout_text;
  }
}

// `resume` of a job that is running (here: waiting for a worker) says there
// is nothing to resume instead of printing a state that reads as a resume.
TEST(Cli, ResumeOfARunningJobSaysThereIsNothingToResume) {
  ScratchDir dir;
  auto server = StartServer(dir.File("jobs.db"), {}, "127.0.0.1:0", dir.File("server.log"));
  ASSERT_TRUE(server.ok()) << server.status();
  auto submitted = Mbopt({"submit", VehicleStudy(), "--server", server->address});
  ASSERT_EQ(submitted.exit_code, kExitOk) << Describe(submitted);
  const std::string job = Trim(submitted.stdout_text);
  auto resumed = Mbopt({"resume", job, "--server", server->address});
  EXPECT_EQ(resumed.exit_code, kExitOk) << Describe(resumed);
  EXPECT_EQ(resumed.stdout_text, job + ": running already; nothing to resume (`mbopt watch " + job + "` follows it)\n");
  auto cancelled = Mbopt({"cancel", job, "--server", server->address});
  EXPECT_EQ(cancelled.exit_code, kExitOk) << Describe(cancelled);
  // A cancelled job may be resumed: that one is a real resume.
  auto resumed_cancelled = Mbopt({"resume", job, "--server", server->address});
  EXPECT_EQ(resumed_cancelled.exit_code, kExitOk) << Describe(resumed_cancelled);
  EXPECT_EQ(resumed_cancelled.stdout_text, job + ": running\n");
  EXPECT_EQ(server->process->Stop(kGuard), 0);
}

// A worker that reports wrong-size vectors: the server refuses the result or
// treats it as a failed analysis, and keeps serving; a job run by real
// workers next to it completes with the undisturbed result.
TEST(BadInput, GarbageResultsDoNotStopTheServer) {
  const std::string reference = Comparable(ReferenceResult(2));
  ASSERT_FALSE(reference.empty());
  ScratchDir dir;
  auto server = StartServer(dir.File("jobs.db"), kFastLeases, "127.0.0.1:0",
                            dir.File("server.log"));
  ASSERT_TRUE(server.ok()) << server.status();
  auto victim = Mbopt({"submit", VehicleStudy(), "--server", server->address});
  ASSERT_EQ(victim.exit_code, kExitOk) << Describe(victim);
  const std::string victim_job = Trim(victim.stdout_text);

  auto channel = grpc::CreateChannel(server->address, grpc::InsecureChannelCredentials());
  auto stub = v1::WorkerService::NewStub(channel);
  v1::RegisterWorkerRequest reg;
  reg.set_name("garbage");
  reg.set_slots(4);
  v1::RegisterWorkerResponse registered;
  {
    grpc::ClientContext context;
    ASSERT_TRUE(stub->Register(&context, reg, &registered).ok());
  }
  v1::AcquireTasksRequest acquire;
  acquire.set_worker_id(registered.worker_id());
  acquire.set_max_tasks(4);
  acquire.set_wait_ms(30000);
  v1::AcquireTasksResponse tasks;
  {
    grpc::ClientContext context;
    ASSERT_TRUE(stub->AcquireTasks(&context, acquire, &tasks).ok());
  }
  ASSERT_GT(tasks.tasks_size(), 0);
  for (const auto& task : tasks.tasks()) {
    v1::TaskResult garbage;
    garbage.set_worker_id(registered.worker_id());
    garbage.set_task_id(task.task_id());
    garbage.set_job_id(task.job_id());
    garbage.set_request_id(task.request_id());
    garbage.set_ok(true);
    garbage.add_objective_terms(1.0);  // far too few terms and rows
    garbage.add_constraint_values(2.0);
    garbage.add_constraint_values(3.0);
    v1::ReportResultResponse response;
    grpc::ClientContext context;
    grpc::Status status = stub->ReportResult(&context, garbage, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
        << "a result that does not fit its task is refused: " << status.error_message();
  }
  ASSERT_TRUE(server->process->running()) << "the server survived garbage";

  std::vector<Subprocess> pool;
  for (int i = 0; i < 2; ++i) pool.push_back(StartWorker(server->address));
  const std::string json = SubmitWatchAndGetResults(server->address);
  EXPECT_EQ(Comparable(json), reference) << "another job is served normally";
  auto victim_end = Mbopt({"watch", victim_job, "--server", server->address});
  EXPECT_TRUE(victim_end.exit_code == kExitOk || victim_end.exit_code == kExitNotConverged ||
              victim_end.exit_code == 4)
      << "the job that got garbage ends too\n" << Describe(victim_end);
  for (auto& w : pool) w.Stop(kGuard);
  EXPECT_EQ(server->process->Stop(kGuard), 0);
}

}  // namespace
}  // namespace mbopt::e2e
