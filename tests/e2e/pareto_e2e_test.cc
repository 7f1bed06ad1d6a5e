// The vehicle's Pareto front (examples/vehicle/vehicle_pareto.study.textproto:
// ride comfort against seat travel, 5 points) through real processes:
// `mbopt run` prints the front, `results` lists it and shows one point,
// `report` draws it, and a server killed mid-front resumes to the same
// front bit for bit ("the same" is `results --json` without the job id and
// the database, compared as text with 17 significant digits).
#include <signal.h>

#include <fstream>
#include <iostream>
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
constexpr int kPoints = 5;
const std::vector<std::string> kFastLeases = {"--lease-ms", "1500", "--heartbeat-ms", "200"};

std::string ParetoStudy() {
  return std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/vehicle/vehicle_pareto.study.textproto";
}

std::string Describe(const Subprocess::Output& out) {
  return absl::StrCat("exit ", out.exit_code, "\nstdout:\n", out.stdout_text, "\nstderr:\n", out.stderr_text);
}

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(ParetoEndToEnd, RunPrintsTheFrontResultsShowAPointAndReportDrawsIt) {
  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()};
  ScratchDir dir;
  const std::string db = dir.File("run.db");
  auto run = Mbopt({"run", ParetoStudy(), "--workers", "2", "--db", db}, env);
  ASSERT_EQ(run.exit_code, kExitOk) << Describe(run);
  const std::string& text = run.stdout_text;
  EXPECT_NE(text.find("points:        5 of 5 on the Pareto front computed"), std::string::npos) << text;
  EXPECT_NE(text.find("status:        completed"), std::string::npos) << text;
  const size_t header = text.find("point ");
  ASSERT_NE(header, std::string::npos) << text;
  for (const char* column : {"level [in]", "F [m/s^2]", "s1 [in]", "maxg", "run", "x6", "status"}) {
    EXPECT_NE(text.find(column, header), std::string::npos) << column << "\n" << text;
  }
  EXPECT_EQ(Count(text.substr(header), "  front\n"), kPoints) << text;

  auto csv = Mbopt({"results", "job-1", "--csv", "--db", db}, env);
  ASSERT_EQ(csv.exit_code, kExitOk) << Describe(csv);
  EXPECT_EQ(csv.stdout_text.rfind("point,level,objective,s1,max_violation,run_state,cycles,analyses,x1,x2,x3,x4,x5,"
                                  "x6,status,reason\n",
                                  0),
            0u)
      << csv.stdout_text;
  EXPECT_EQ(Count(csv.stdout_text, "\n"), kPoints + 1) << csv.stdout_text;

  auto point = Mbopt({"results", "job-1", "--point", "3", "--db", db}, env);
  ASSERT_EQ(point.exit_code, kExitOk) << Describe(point);
  EXPECT_NE(point.stdout_text.find("point 3 of 5 (front)"), std::string::npos) << point.stdout_text;
  EXPECT_NE(point.stdout_text.find("level:       s1 <= "), std::string::npos) << point.stdout_text;
  EXPECT_NE(point.stdout_text.find("seat_settles"), std::string::npos) << point.stdout_text;
  auto no_point = Mbopt({"results", "job-1", "--point", "6", "--db", db}, env);
  EXPECT_NE(no_point.exit_code, kExitOk);
  EXPECT_NE(no_point.stderr_text.find("--point 6: job job-1 has points 1 to 5 (of 5)"), std::string::npos)
      << Describe(no_point);

  const std::string page = dir.File("front.html");
  auto report = Mbopt({"report", "job-1", "--db", db, "-o", page, "--point", "3"}, env);
  ASSERT_EQ(report.exit_code, kExitOk) << Describe(report);
  std::ifstream in(page);
  std::stringstream html;
  html << in.rdbuf();
  EXPECT_NE(html.str().find("<svg"), std::string::npos);
  EXPECT_NE(html.str().find("Pareto front"), std::string::npos);
  EXPECT_NE(html.str().find("chosen: point 3"), std::string::npos);
  // Point 3's responses, analysed by the worker program at its design: the
  // objective's seat acceleration and each constraint's output over time.
  EXPECT_NE(html.str().find("<h2>Responses of point 3</h2>"), std::string::npos) << html.str();
  EXPECT_EQ(html.str().find("The responses are not shown"), std::string::npos) << html.str();
  for (const char* plot : {"objective: ", "s1: ", "seat_settles: "}) {
    EXPECT_NE(html.str().find(plot, html.str().find("Responses of point 3")), std::string::npos) << plot;
  }
  EXPECT_GE(Count(html.str(), "<svg"), 1 + 7) << "the front, the objective and six constraints";
}

// Submits the front to a fresh server with `workers` workers and returns
// `results --json` at its end.
std::string FrontResults(int workers, const std::string& study = ParetoStudy()) {
  ScratchDir dir;
  auto server = StartServer(dir.File("jobs.db"), {}, "127.0.0.1:0", dir.File("server.log"));
  EXPECT_TRUE(server.ok()) << server.status();
  if (!server.ok()) return "";
  std::vector<Subprocess> pool;
  for (int i = 0; i < workers; ++i) {
    pool.push_back(StartWorker(server->address, {}, dir.File(absl::StrCat("worker", i, ".log"))));
  }
  auto submitted = Mbopt({"submit", study, "--server", server->address});
  EXPECT_EQ(submitted.exit_code, kExitOk) << Describe(submitted);
  const std::string job = Trim(submitted.stdout_text);
  auto watched = Mbopt({"watch", job, "--server", server->address});
  EXPECT_EQ(watched.exit_code, kExitOk) << Describe(watched);
  auto results = Mbopt({"results", job, "--json", "--server", server->address});
  EXPECT_EQ(results.exit_code, kExitOk) << Describe(results);
  for (auto& w : pool) w.Stop(kGuard);
  EXPECT_EQ(server->process->Stop(kGuard), 0);
  return results.stdout_text;
}

// The server is killed (SIGKILL) once it has logged `crash_after` points;
// the restarted server replays the logged analyses (the runs of the points
// not yet ended among them) and continues: the front is that of an
// undisturbed run with another number of workers, bit for bit.
void KillAndResume(const std::string& study, int points, int crash_after) {
  const std::string reference = Comparable(FrontResults(3, study));
  ASSERT_FALSE(reference.empty());
  EXPECT_EQ(JsonField(reference, "points_done"), std::to_string(points)) << reference;
  ScratchDir dir;
  const std::string db = dir.File("jobs.db");
  std::vector<std::string> crash_args = kFastLeases;
  crash_args.insert(crash_args.end(), {"--crash-after-cycles", std::to_string(crash_after)});
  auto first = StartServer(db, crash_args, "127.0.0.1:0", dir.File("server1.log"));
  ASSERT_TRUE(first.ok()) << first.status();
  std::vector<Subprocess> pool;
  for (int i = 0; i < 2; ++i) {
    pool.push_back(StartWorker(first->address, {}, dir.File(absl::StrCat("worker", i, ".log"))));
  }
  auto submitted = Mbopt({"submit", study, "--server", first->address});
  ASSERT_EQ(submitted.exit_code, kExitOk) << Describe(submitted);
  const std::string job = Trim(submitted.stdout_text);
  auto crashed = first->process->Wait(kGuard);
  ASSERT_TRUE(crashed.ok()) << crashed.status();
  ASSERT_EQ(*crashed, kKilledBySigkill);

  auto second = StartServer(db, kFastLeases, absl::StrCat("127.0.0.1:", first->port), dir.File("server2.log"));
  ASSERT_TRUE(second.ok()) << second.status();
  auto status = Mbopt({"status", job, "--server", second->address});
  ASSERT_EQ(status.exit_code, kExitOk) << Describe(status);
  const size_t at = status.stdout_text.find("points:");
  ASSERT_NE(at, std::string::npos) << status.stdout_text;
  const int points_at_restart = std::atoi(status.stdout_text.c_str() + at + 7);
  EXPECT_GE(points_at_restart, crash_after) << status.stdout_text;
  std::cout << "points logged when the server was killed: " << points_at_restart << " of " << points << "\n";
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

TEST(ParetoEndToEnd, ServerKilledMidFrontResumesWithTheSameFront) { KillAndResume(ParetoStudy(), kPoints, 2); }

// The example with `refine: 2`, killed once the first five points and one
// added point are logged: the other added point's run is replayed and
// continued, and the refined front is that of an undisturbed run.
TEST(ParetoEndToEnd, ServerKilledWhileRefiningResumesWithTheSameFront) {
  ScratchDir dir;
  const std::string examples = std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/vehicle/";
  std::ifstream scene(examples + "vehicle.scene.textproto");
  std::ifstream pareto(ParetoStudy());
  std::stringstream scene_text, study_text;
  scene_text << scene.rdbuf();
  study_text << pareto.rdbuf();
  std::string study = study_text.str();
  const std::string section = "pareto { against: \"s1\" points: 5 }";
  const size_t at = study.find(section);
  ASSERT_NE(at, std::string::npos) << "the example's pareto section changed";
  study.replace(at, section.size(), "pareto { against: \"s1\" points: 5 refine: 2 }");
  dir.Write("vehicle.scene.textproto", scene_text.str());
  KillAndResume(dir.Write("vehicle_pareto_refined.study.textproto", study), kPoints + 2, kPoints + 1);
}

TEST(ParetoEndToEnd, ValidateNamesTheFront) {
  auto validated = Mbopt({"validate", ParetoStudy()});
  ASSERT_EQ(validated.exit_code, kExitOk) << Describe(validated);
  EXPECT_NE(validated.stdout_text.find("form:        a Pareto front of the objective against the largest value of "
                                       "s1 (in), 5 points (epsilon-constraint method)"),
            std::string::npos)
      << validated.stdout_text;
}

}  // namespace
}  // namespace mbopt::e2e
