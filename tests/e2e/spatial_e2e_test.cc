// examples/spatial through the service: `mbopt run` starts a server and
// workers that analyse the flyball governor's spatial scene by finite
// differences; the study converges, and one worker gives the same result as
// two.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/e2e/e2e_harness.h"

namespace mbopt::e2e {
namespace {

TEST(SpatialEndToEnd, GovernorStudyConvergesThroughMboptRunWithTheSameResultOnOneAndTwoWorkers) {
  const std::string study = std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/spatial/governor.study.textproto";
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
