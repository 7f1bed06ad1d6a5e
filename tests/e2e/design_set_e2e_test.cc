// A sweep (examples/vehicle/vehicle_sweep.study.textproto: the front spring
// over 9 designs) through real processes: `mbopt run` prints every design,
// the table is the same with 1 and 3 workers and after a server killed
// mid-sweep, and a design's values are those of one `mbopt-worker eval` of
// that design, bit for bit. "The same table" is `results --json` without the
// job id and the database, compared as text (17 significant digits).
#include <signal.h>

#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "tests/e2e/e2e_harness.h"

namespace mbopt::e2e {
namespace {

using client::Subprocess;

constexpr int kExitOk = 0;
constexpr int kKilledBySigkill = 128 + SIGKILL;
constexpr int kDesigns = 9;
const std::vector<std::string> kFastLeases = {"--lease-ms", "1500", "--heartbeat-ms", "200"};

std::string SweepStudy() {
  return std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/vehicle/vehicle_sweep.study.textproto";
}

std::string Describe(const Subprocess::Output& out) {
  return absl::StrCat("exit ", out.exit_code, "\nstdout:\n", out.stdout_text, "\nstderr:\n", out.stderr_text);
}

// Every `"key": value` of `json` whose key is `key`, in order (the values of
// the designs' entries).
std::vector<std::string> AllFields(const std::string& json, const std::string& key) {
  std::vector<std::string> values;
  const std::string needle = "\"" + key + "\": ";
  for (size_t pos = json.find(needle); pos != std::string::npos; pos = json.find(needle, pos + 1)) {
    const size_t start = pos + needle.size();
    const size_t end = json.find_first_of(",\n}", start);
    values.push_back(json.substr(start, end - start));
  }
  return values;
}

// Submits the sweep to a fresh server with `workers` workers, follows it to
// its end and returns `results --json`.
std::string SweepResults(int workers) {
  ScratchDir dir;
  auto server = StartServer(dir.File("jobs.db"), {}, "127.0.0.1:0", dir.File("server.log"));
  EXPECT_TRUE(server.ok()) << server.status();
  if (!server.ok()) return "";
  std::vector<Subprocess> pool;
  for (int i = 0; i < workers; ++i) {
    pool.push_back(StartWorker(server->address, {}, dir.File(absl::StrCat("worker", i, ".log"))));
  }
  auto submitted = Mbopt({"submit", SweepStudy(), "--server", server->address});
  EXPECT_EQ(submitted.exit_code, kExitOk) << Describe(submitted);
  const std::string job = Trim(submitted.stdout_text);
  auto watched = Mbopt({"watch", job, "--server", server->address});
  EXPECT_EQ(watched.exit_code, kExitOk) << Describe(watched);
  EXPECT_NE(watched.stdout_text.find("design"), std::string::npos) << watched.stdout_text;
  EXPECT_NE(watched.stdout_text.find(absl::StrCat(job, ": completed after ", kDesigns, " designs")),
            std::string::npos)
      << watched.stdout_text;
  auto results = Mbopt({"results", job, "--json", "--server", server->address});
  EXPECT_EQ(results.exit_code, kExitOk) << Describe(results);
  for (auto& w : pool) w.Stop(kGuard);
  EXPECT_EQ(server->process->Stop(kGuard), 0);
  return results.stdout_text;
}

TEST(DesignSetEndToEnd, RunPrintsEveryDesignAndTheTable) {
  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()};
  ScratchDir dir;
  auto run = Mbopt({"run", SweepStudy(), "--workers", "2", "--db", dir.File("run.db")}, env);
  ASSERT_EQ(run.exit_code, kExitOk) << Describe(run);
  const std::string& text = run.stdout_text;
  EXPECT_NE(text.find("designs:       9 of 9 analysed"), std::string::npos) << text;
  EXPECT_NE(text.find("status:        completed"), std::string::npos) << text;
  EXPECT_NE(text.find("best design:"), std::string::npos) << text;
  // The table's header names the variables, F with its unit, maxg, each
  // constraint and the status; then one row per design.
  const size_t header = text.find("  design ");
  ASSERT_NE(header, std::string::npos) << text;
  for (const char* column : {"x2", "F [m/s^2]", "maxg", "s1", "s5", "status"}) {
    EXPECT_NE(text.find(column, header), std::string::npos) << column << "\n" << text;
  }
  int ok_rows = 0;
  std::istringstream lines(text.substr(header));
  for (std::string line; std::getline(lines, line);) ok_rows += line.size() > 4 && line.substr(line.size() - 4) == "  ok";
  EXPECT_EQ(ok_rows, kDesigns) << text;

  auto csv = Mbopt({"results", "job-1", "--csv", "--db", dir.File("run.db")}, env);
  ASSERT_EQ(csv.exit_code, kExitOk) << Describe(csv);
  EXPECT_EQ(csv.stdout_text.rfind("design,x1,x2,x3,x4,x5,x6,objective,max_violation,s1,s2,s3,s4,s5,status,"
                                  "failure_reason\n",
                                  0),
            0u)
      << csv.stdout_text;
  int csv_rows = 0;
  for (char c : csv.stdout_text) csv_rows += c == '\n';
  EXPECT_EQ(csv_rows, kDesigns + 1) << csv.stdout_text;
  // k2 = 20 x2 from 150 to 600 lbf/in: the CSV's design values are physical.
  EXPECT_NE(csv.stdout_text.find("\n1,100,150,300,"), std::string::npos) << csv.stdout_text;
  EXPECT_NE(csv.stdout_text.find("\n9,100,600,300,"), std::string::npos) << csv.stdout_text;

  auto status = Mbopt({"status", "job-1", "--db", dir.File("run.db")}, env);
  EXPECT_EQ(status.exit_code, kExitOk) << Describe(status);
  EXPECT_NE(status.stdout_text.find("designs:       9 of 9 analysed"), std::string::npos) << status.stdout_text;
}

TEST(DesignSetEndToEnd, SameTableWithOneAndThreeWorkers) {
  const std::string one = Comparable(SweepResults(1));
  ASSERT_FALSE(one.empty());
  EXPECT_EQ(AllFields(one, "status").size(), static_cast<size_t>(kDesigns) + 1) << one;
  EXPECT_EQ(JsonField(one, "designs_done"), std::to_string(kDesigns)) << one;
  EXPECT_EQ(Comparable(SweepResults(3)), one);
}

// One design of the sweep is one analysis: its objective and largest
// normalized constraint value are those `mbopt-worker eval` prints for the
// same design, bit for bit.
TEST(DesignSetEndToEnd, EveryDesignIsTheWorkersEvaluationOfIt) {
  const std::string json = SweepResults(2);
  const std::vector<std::string> objectives = AllFields(json, "objective");
  const std::vector<std::string> violations = AllFields(json, "max_violation");
  // Design k + 1 (k from 0) has x2 = 7.5 + 2.8125 k, scaled as in the study.
  ASSERT_EQ(objectives.size(), static_cast<size_t>(kDesigns)) << json;
  ASSERT_EQ(violations.size(), static_cast<size_t>(kDesigns)) << json;
  for (int k : {0, 4, 8}) {
    const std::string x2 = absl::StrCat(7.5 + 2.8125 * k);
    auto eval = client::RunCommand({WorkerBinary(), "eval", SweepStudy(), "--set", "x2=" + x2, "--json"}, kGuard);
    ASSERT_TRUE(eval.ok()) << eval.status();
    ASSERT_EQ(eval->exit_code, 0) << Describe(*eval);
    const std::string& one = eval->stdout_text;
    EXPECT_NE(one.find("\"x2\": " + x2), std::string::npos) << one;
    EXPECT_NE(one.find("\"objective\": " + objectives[static_cast<size_t>(k)] + ","), std::string::npos)
        << "design " << k + 1 << ": the sweep gave F = " << objectives[static_cast<size_t>(k)] << "\n" << one;
    EXPECT_NE(one.find("\"max_violation\": " + violations[static_cast<size_t>(k)] + ","), std::string::npos)
        << "design " << k + 1 << ": the sweep gave maxg = " << violations[static_cast<size_t>(k)] << "\n" << one;
  }
}

// The server is killed (SIGKILL) once it has logged three designs; the
// restarted server continues the sweep and the table is that of an
// undisturbed run. The workers take one task at a time (--batch 1): by
// default a worker takes many of these cheap analyses at once and reports
// their results in one call, one commit, so the kill could find the sweep
// already complete.
TEST(DesignSetEndToEnd, ServerKilledMidSweepResumesWithTheSameTable) {
  const std::string reference = Comparable(SweepResults(2));
  ASSERT_FALSE(reference.empty());
  ScratchDir dir;
  const std::string db = dir.File("jobs.db");
  std::vector<std::string> crash_args = kFastLeases;
  crash_args.insert(crash_args.end(), {"--crash-after-cycles", "3"});
  auto first = StartServer(db, crash_args, "127.0.0.1:0", dir.File("server1.log"));
  ASSERT_TRUE(first.ok()) << first.status();
  std::vector<Subprocess> pool;
  for (int i = 0; i < 2; ++i) {
    pool.push_back(StartWorker(first->address, {"--batch", "1"}, dir.File(absl::StrCat("worker", i, ".log"))));
  }
  auto submitted = Mbopt({"submit", SweepStudy(), "--server", first->address});
  ASSERT_EQ(submitted.exit_code, kExitOk) << Describe(submitted);
  const std::string job = Trim(submitted.stdout_text);
  auto crashed = first->process->Wait(kGuard);
  ASSERT_TRUE(crashed.ok()) << crashed.status();
  ASSERT_EQ(*crashed, kKilledBySigkill);

  auto second = StartServer(db, kFastLeases, absl::StrCat("127.0.0.1:", first->port), dir.File("server2.log"));
  ASSERT_TRUE(second.ok()) << second.status();
  auto status = Mbopt({"status", job, "--server", second->address});
  ASSERT_EQ(status.exit_code, kExitOk) << Describe(status);
  const size_t at = status.stdout_text.find("designs:");
  ASSERT_NE(at, std::string::npos) << status.stdout_text;
  const int designs_at_restart = std::atoi(status.stdout_text.c_str() + at + 8);
  EXPECT_GE(designs_at_restart, 3) << status.stdout_text;
  // Designs are logged in their order, so a design finished early waits for
  // the one before it and may be logged with it: a few past the third, not all.
  EXPECT_LT(designs_at_restart, kDesigns) << "the kill fell in the middle of the sweep\n" << status.stdout_text;
  if (status.stdout_text.find("interrupted") != std::string::npos) {
    auto resumed = Mbopt({"resume", job, "--server", second->address});
    ASSERT_EQ(resumed.exit_code, kExitOk) << Describe(resumed);
  }
  auto watched = Mbopt({"watch", job, "--server", second->address});
  ASSERT_EQ(watched.exit_code, kExitOk) << Describe(watched);
  auto results = Mbopt({"results", job, "--json", "--server", second->address});
  EXPECT_EQ(Comparable(results.stdout_text), reference);
  for (auto& w : pool) EXPECT_EQ(w.Stop(kGuard), 0);
  EXPECT_EQ(second->process->Stop(kGuard), 0);
}

TEST(DesignSetEndToEnd, ValidateNamesTheSweep) {
  auto validated = Mbopt({"validate", SweepStudy()});
  ASSERT_EQ(validated.exit_code, kExitOk) << Describe(validated);
  EXPECT_NE(validated.stdout_text.find("form:        a sweep of x2 (9 points from 7.5 to 30, scaled)"),
            std::string::npos)
      << validated.stdout_text;
}

}  // namespace
}  // namespace mbopt::e2e
