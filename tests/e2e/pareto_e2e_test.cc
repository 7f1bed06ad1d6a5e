// The vehicle's Pareto front (examples/vehicle/vehicle_pareto.study.textproto:
// ride comfort against seat travel, 5 points) through real processes:
// `mbopt run` prints the front, `results` lists it and shows one point,
// `report` draws it, and a server killed mid-front resumes to the same
// front bit for bit, its points' runs' histories included ("the same" is
// `results --json` without the job id and the database, compared as text
// with 17 significant digits). A second objective of its own
// (examples/vehicle/vehicle_pareto_travel.study.textproto) and a maximized
// one run the same way.
#include <signal.h>

#include <cstdlib>
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
  // Its run's cycles, as a single job's table lists them.
  const size_t history = point.stdout_text.find("cycles of its run (F: the study's objective;");
  ASSERT_NE(history, std::string::npos) << point.stdout_text;
  EXPECT_NE(point.stdout_text.find("cycle att", history), std::string::npos) << point.stdout_text;
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
  EXPECT_NE(html.str().find("<h2>Cycle history of point 3's run</h2>"), std::string::npos) << html.str();
  EXPECT_NE(html.str().find("<table class=\"cycles\""), std::string::npos);
  // Point 3's responses, analysed by the worker program at its design: the
  // objective's seat acceleration and each constraint's output over time.
  EXPECT_NE(html.str().find("<h2>Responses of point 3</h2>"), std::string::npos) << html.str();
  EXPECT_EQ(html.str().find("The responses are not shown"), std::string::npos) << html.str();
  for (const char* plot : {"objective: ", "s1: ", "seat_settles: "}) {
    EXPECT_NE(html.str().find(plot, html.str().find("Responses of point 3")), std::string::npos) << plot;
  }
  EXPECT_GE(Count(html.str(), "<svg"), 1 + 5 + 7)
      << "the front, the run's five history plots, the objective and six constraints";
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> SplitOn(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, separator);) parts.push_back(part);
  return parts;
}

// The vehicle example whose second objective is an objective of its own
// (the peak travel of the axles' suspensions), through `mbopt run`: the
// printed front names it and gives every point on it, in inches.
TEST(ParetoEndToEnd, TheTravelExampleRunsItsSecondObjectiveThroughTheCli) {
  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()};
  ScratchDir dir;
  const std::string db = dir.File("run.db");
  const std::string study =
      std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/vehicle/vehicle_pareto_travel.study.textproto";
  auto run = Mbopt({"run", study, "--workers", "2", "--db", db}, env);
  ASSERT_EQ(run.exit_code, kExitOk) << Describe(run);
  const std::string& text = run.stdout_text;
  EXPECT_NE(text.find("points:        5 of 5 on the Pareto front computed"), std::string::npos) << text;
  EXPECT_NE(text.find("F2: largest of 2 terms [in]"), std::string::npos) << text;
  auto csv = Mbopt({"results", "job-1", "--csv", "--db", db}, env);
  ASSERT_EQ(csv.exit_code, kExitOk) << Describe(csv);
  const std::vector<std::string> lines = SplitOn(csv.stdout_text, '\n');
  ASSERT_EQ(lines.size(), static_cast<size_t>(kPoints + 1)) << csv.stdout_text;
  EXPECT_EQ(lines[0].rfind("point,level,objective,second_objective,", 0), 0u) << lines[0];
  // Along the front the objective rises as the travel falls.
  double previous_travel = 0, previous_objective = 0;
  for (int k = 1; k <= kPoints; ++k) {
    const std::vector<std::string> cells = SplitOn(lines[static_cast<size_t>(k)], ',');
    ASSERT_GE(cells.size(), 4u) << lines[static_cast<size_t>(k)];
    const double objective = std::atof(cells[2].c_str());
    const double travel_in = std::atof(cells[3].c_str());
    EXPECT_GT(travel_in, 0.0) << lines[static_cast<size_t>(k)];
    EXPECT_LE(travel_in, 1.5 + 1e-3) << "the front suspension's own limit holds";
    if (k > 1) {
      EXPECT_LT(travel_in, previous_travel) << lines[static_cast<size_t>(k)];
      EXPECT_GE(objective, previous_objective * (1 - 1e-9)) << lines[static_cast<size_t>(k)];
    }
    previous_travel = travel_in;
    previous_objective = objective;
  }
}

// A maximized second objective through every way the CLI shows it: the
// axle springs' sum k2 + k3 (a response of the design alone, so its value
// at each point is known from the point's design) is shown as itself, not
// as the negative the runs minimize: in the lines `mbopt run` prints as the
// points arrive, in `results` and on the report page.
TEST(ParetoEndToEnd, AMaximizedSecondObjectiveIsShownAsItselfByRunResultsAndReport) {
  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()};
  ScratchDir dir;
  const std::string examples = std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/vehicle/";
  std::string study = ReadText(ParetoStudy());
  const std::string section = "pareto { against: \"s1\" points: 5 }";
  const size_t at = study.find(section);
  ASSERT_NE(at, std::string::npos) << "the example's pareto section changed";
  study.replace(at, section.size(),
                "responses { name: \"axle_springs\" expr: \"k2 + k3\" unit: \"lbf/in\" }\n"
                "pareto { objective { maximize: \"axle_springs\" unit: \"lbf/in\" } points: 3 }");
  dir.Write("vehicle.scene.textproto", ReadText(examples + "vehicle.scene.textproto"));
  const std::string path = dir.Write("vehicle_springs.study.textproto", study);
  const std::string db = dir.File("run.db");
  auto run = Mbopt({"run", path, "--workers", "2", "--db", db}, env);
  ASSERT_EQ(run.exit_code, kExitOk) << Describe(run);
  const std::string& text = run.stdout_text;
  const std::string label = "F2: axle_springs (maximized) [lbf/in]";
  // The watch's lines: a header, then a line per point whose second
  // objective and level (its third and fourth cells) are not negative.
  const size_t header = text.find("point");
  ASSERT_NE(header, std::string::npos) << text;
  const std::vector<std::string> watch = SplitOn(text.substr(header), '\n');
  ASSERT_GE(watch.size(), 4u) << text;
  EXPECT_NE(watch[0].find(label), std::string::npos) << watch[0];
  for (int k = 1; k <= 3; ++k) {
    std::stringstream cells(watch[static_cast<size_t>(k)]);
    std::string point, objective, second, level;
    cells >> point >> objective >> second >> level;
    EXPECT_EQ(point, std::to_string(k)) << text;
    EXPECT_GT(std::atof(second.c_str()), 0.0) << watch[static_cast<size_t>(k)];
    EXPECT_TRUE(level == "-" || std::atof(level.c_str()) > 0.0) << watch[static_cast<size_t>(k)];
  }
  auto csv = Mbopt({"results", "job-1", "--csv", "--db", db}, env);
  ASSERT_EQ(csv.exit_code, kExitOk) << Describe(csv);
  const std::vector<std::string> lines = SplitOn(csv.stdout_text, '\n');
  ASSERT_EQ(lines.size(), 4u) << csv.stdout_text;
  ASSERT_EQ(lines[0].rfind("point,level,objective,second_objective,max_violation,run_state,cycles,analyses,x1,x2,x3,",
                           0),
            0u)
      << lines[0];
  std::vector<double> springs;
  for (int k = 1; k <= 3; ++k) {
    const std::vector<std::string> cells = SplitOn(lines[static_cast<size_t>(k)], ',');
    ASSERT_GE(cells.size(), 11u) << lines[static_cast<size_t>(k)];
    const double second = std::atof(cells[3].c_str());
    // x2 and x3 are k2 and k3 in lbf/in.
    const double k2_plus_k3 = std::atof(cells[9].c_str()) + std::atof(cells[10].c_str());
    EXPECT_NEAR(second, k2_plus_k3, 1e-6 * k2_plus_k3) << lines[static_cast<size_t>(k)];
    springs.push_back(second);
  }
  // The far end is the stiffest design the other constraints allow; the
  // point between is held at or above its level, halfway.
  EXPECT_GT(springs[2], springs[0]) << csv.stdout_text;
  const double level = std::atof(SplitOn(lines[2], ',')[1].c_str());
  EXPECT_NEAR(level, 0.5 * (springs[0] + springs[2]), 1e-9 * springs[2]) << lines[2];
  EXPECT_GE(springs[1], level * (1 - 1e-4)) << lines[2];

  auto point = Mbopt({"results", "job-1", "--point", "2", "--db", db}, env);
  ASSERT_EQ(point.exit_code, kExitOk) << Describe(point);
  EXPECT_NE(point.stdout_text.find("level:       F2: axle_springs (maximized) >= "), std::string::npos)
      << point.stdout_text;
  const std::string page = dir.File("front.html");
  auto report = Mbopt({"report", "job-1", "--db", db, "-o", page}, env);
  ASSERT_EQ(report.exit_code, kExitOk) << Describe(report);
  const std::string html = ReadText(page);
  EXPECT_NE(html.find("held above the point's level"), std::string::npos);
  EXPECT_NE(html.find("<th>traded against</th><td>the second objective F2: axle_springs (maximized)</td>"),
            std::string::npos);
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

// The records a front logs up to and including point `point`'s (1-based):
// each point's run's cycle records (its "history" in `results --json`, one
// object per LP solve), then the point's own.
int RecordsThroughPoint(const std::string& results_json, int point) {
  const std::string point_key = "\"point\": ";
  int records = 0;
  size_t at = results_json.find(point_key);
  for (int k = 1; k <= point && at != std::string::npos; ++k) {
    const size_t next = results_json.find(point_key, at + 1);
    const std::string object = results_json.substr(at, next == std::string::npos ? std::string::npos : next - at);
    records += Count(object, "\"attempt\": ") + 1;
    at = next;
  }
  return records;
}

// The server is killed (SIGKILL) once it has logged `crash_after` points
// (their runs' cycle records with them); the restarted server replays the
// logged analyses (the runs of the points not yet ended among them) and
// continues: the front, and every point's run's cycle history, is that of
// an undisturbed run with another number of workers, bit for bit.
void KillAndResume(const std::string& study, int points, int crash_after) {
  const std::string reference = Comparable(FrontResults(3, study));
  ASSERT_FALSE(reference.empty());
  EXPECT_EQ(JsonField(reference, "points_done"), std::to_string(points)) << reference;
  const int crash_after_records = RecordsThroughPoint(reference, crash_after);
  // Every run logs a cycle at least, before its point's record.
  ASSERT_GE(crash_after_records, 2 * crash_after) << reference;
  ScratchDir dir;
  const std::string db = dir.File("jobs.db");
  std::vector<std::string> crash_args = kFastLeases;
  crash_args.insert(crash_args.end(), {"--crash-after-cycles", std::to_string(crash_after_records)});
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

std::string ThreeObjectiveStudy() {
  return std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/vehicle/vehicle_pareto3.study.textproto";
}

// The front of three objectives (comfort against |s1| and |s2|, 3 anchors
// and a 3 x 3 grid) through `mbopt run`, `results` and `report`: both
// traded constraints' values and levels in every listing, and the page's
// three projections.
TEST(ParetoEndToEnd, AFrontOfThreeObjectivesRunsThroughTheCliAndTheReportDrawsItsProjections) {
  constexpr int kThreePoints = 3 + 3 * 3;
  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()};
  ScratchDir dir;
  const std::string db = dir.File("run.db");
  auto run = Mbopt({"run", ThreeObjectiveStudy(), "--workers", "2", "--db", db}, env);
  ASSERT_EQ(run.exit_code, kExitOk) << Describe(run);
  const std::string& text = run.stdout_text;
  EXPECT_NE(text.find("points:        12 of 12 on the Pareto front computed"), std::string::npos) << text;
  const size_t header = text.find("point ");
  ASSERT_NE(header, std::string::npos) << text;
  for (const char* column : {"level [in]", "level3 [in]", "F [m/s^2]", "s1 [in]", "s2 [in]", "status"}) {
    EXPECT_NE(text.find(column, header), std::string::npos) << column << "\n" << text;
  }
  auto csv = Mbopt({"results", "job-1", "--csv", "--db", db}, env);
  ASSERT_EQ(csv.exit_code, kExitOk) << Describe(csv);
  const std::vector<std::string> lines = SplitOn(csv.stdout_text, '\n');
  ASSERT_EQ(lines.size(), static_cast<size_t>(kThreePoints + 1)) << csv.stdout_text;
  EXPECT_EQ(lines[0].rfind("point,level,level3,objective,s1,s2,max_violation,", 0), 0u) << lines[0];
  // Every grid point meets both its levels (the method's violation
  // tolerance, 1e-3 relative).
  for (int k = 4; k <= kThreePoints; ++k) {
    const std::vector<std::string> cells = SplitOn(lines[static_cast<size_t>(k)], ',');
    ASSERT_GE(cells.size(), 6u) << lines[static_cast<size_t>(k)];
    EXPECT_LE(std::atof(cells[4].c_str()), std::atof(cells[1].c_str()) * (1 + 1e-3)) << lines[static_cast<size_t>(k)];
    EXPECT_LE(std::atof(cells[5].c_str()), std::atof(cells[2].c_str()) * (1 + 1e-3)) << lines[static_cast<size_t>(k)];
  }
  auto json = Mbopt({"results", "job-1", "--json", "--db", db}, env);
  ASSERT_EQ(json.exit_code, kExitOk) << Describe(json);
  EXPECT_NE(json.stdout_text.find("\"against3\": \"s2\""), std::string::npos) << json.stdout_text;
  EXPECT_EQ(Count(json.stdout_text, "\"value3\": "), kThreePoints) << json.stdout_text;
  auto point = Mbopt({"results", "job-1", "--point", "8", "--db", db}, env);
  ASSERT_EQ(point.exit_code, kExitOk) << Describe(point);
  EXPECT_NE(point.stdout_text.find("level3:      s2 <= "), std::string::npos) << point.stdout_text;
  auto anchor = Mbopt({"results", "job-1", "--point", "3", "--db", db}, env);
  ASSERT_EQ(anchor.exit_code, kExitOk) << Describe(anchor);
  EXPECT_NE(anchor.stdout_text.find("cycles of its run (F: the third objective s2 [in], which the run optimizes"),
            std::string::npos)
      << anchor.stdout_text;
  const std::string page = dir.File("front.html");
  auto report = Mbopt({"report", "job-1", "--db", db, "-o", page, "--point", "8", "--no-responses"}, env);
  ASSERT_EQ(report.exit_code, kExitOk) << Describe(report);
  const std::string html = ReadText(page);
  for (const char* title : {"F against s1", "F against s2", "s2 against s1"}) {
    EXPECT_NE(html.find(title), std::string::npos) << title;
  }
  EXPECT_EQ(Count(html, "chosen: point 8"), 3) << html;
  EXPECT_NE(html.find("<h2>Cycle history of point 8's run</h2>"), std::string::npos);
}

// Killed once five of its twelve points are logged, the front of three
// objectives resumes to the front of an undisturbed run with three workers.
TEST(ParetoEndToEnd, ServerKilledMidFrontOfThreeObjectivesResumesWithTheSameFront) {
  KillAndResume(ThreeObjectiveStudy(), 3 + 3 * 3, 5);
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
