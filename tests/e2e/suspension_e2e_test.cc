// examples/suspension through the service: `mbopt run` starts a server and
// workers that analyse the double-wishbone suspension kinematically (a
// fully driven spatial scene) by finite differences; the study converges
// with a small fraction of its start's bump steer, and one worker gives
// the same result as two. The job's report draws the suspension (a sheet
// of four views) at the initial and the final design, and `mbopt draw`
// draws the scene alone.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/e2e/e2e_harness.h"

namespace mbopt::e2e {
namespace {

// Half the toe range of the starting hardpoints over +-80 mm, deg (the
// objective; SpatialKinematics.SuspensionExampleHoldsItsLinksAndFollowsTheTravel
// measures the range, 6.15 deg, from the scene).
constexpr double kStartHalfRangeDeg = 3.07;

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

std::string ReadFile(const std::string& path) {
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  return text.str();
}

TEST(SuspensionEndToEnd, BumpSteerStudyConvergesThroughMboptRunWithTheSameResultOnOneAndTwoWorkers) {
  const std::string study = std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/suspension/suspension.study.textproto";
  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()};
  auto two = Mbopt({"run", study, "--workers", "2", "--json", "--discard-db"}, env);
  ASSERT_EQ(two.exit_code, 0) << two.stdout_text << two.stderr_text;
  EXPECT_EQ(JsonField(two.stdout_text, "status"), "converged") << two.stdout_text;
  EXPECT_LT(std::stod(JsonField(two.stdout_text, "objective")), 0.01 * kStartHalfRangeDeg) << two.stdout_text;
  ScratchDir dir;
  const std::string db = dir.File("suspension.db");
  auto one = Mbopt({"run", study, "--workers", "1", "--json", "--db", db}, env);
  ASSERT_EQ(one.exit_code, 0) << one.stdout_text << one.stderr_text;
  EXPECT_EQ(Comparable(one.stdout_text), Comparable(two.stdout_text));

  // The report of the kept job draws the mechanism at both designs.
  const std::string page = dir.File("suspension.html");
  auto report = Mbopt({"report", "job-1", "--db", db, "-o", page}, env);
  ASSERT_EQ(report.exit_code, 0) << report.stdout_text << report.stderr_text;
  const std::string html = ReadFile(page);
  EXPECT_NE(html.find("<h2>Mechanism</h2>"), std::string::npos);
  EXPECT_EQ(Count(html, "<svg class=\"drawing spatial\""), 1) << "the suspension's sheet of views";
  EXPECT_EQ(Count(html, "<g class=\"view\""), 4);
  EXPECT_NE(html.find(">initial design</text>"), std::string::npos) << "both designs drawn";
  EXPECT_NE(html.find(">final design</text>"), std::string::npos) << "both designs drawn";
  EXPECT_EQ(html.find("are drawn; this job's scene is of another kind"), std::string::npos);
}

// `mbopt draw SCENE` runs `mbopt-worker draw` and writes the page: the
// four views animated over the 33 instants of the travel.
TEST(SuspensionEndToEnd, DrawWritesTheSheetOfViewsOverTheTravel) {
  const std::string scene = std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/suspension/suspension.scene.textproto";
  ScratchDir out;
  const std::string page = out.File("suspension.html");
  auto drawn = Mbopt({"draw", scene, "-o", page}, {"MBOPT_WORKER_BIN=" + WorkerBinary()});
  ASSERT_EQ(drawn.exit_code, 0) << drawn.stdout_text << drawn.stderr_text;
  EXPECT_NE(drawn.stdout_text.find("(33 instants)"), std::string::npos) << drawn.stdout_text;
  const std::string html = ReadFile(page);
  EXPECT_EQ(Count(html, "<g class=\"frame\""), 33);
  EXPECT_EQ(Count(html, "<g class=\"view\""), 4);
  EXPECT_EQ(Count(html, "<input type=\"range\""), 1);
  EXPECT_EQ(html.find("http"), std::string::npos) << "nothing fetched";
}

}  // namespace
}  // namespace mbopt::e2e
