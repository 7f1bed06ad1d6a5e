// examples/fmu through the service: `mbopt run` starts a server and two
// workers, which open the FMU for every analysis; the same study gives the
// same result with one worker and with two.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "absl/strings/str_cat.h"
#include "tests/e2e/e2e_harness.h"

namespace mbopt::e2e {
namespace {

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

}  // namespace
}  // namespace mbopt::e2e
