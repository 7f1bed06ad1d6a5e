// examples/suspension through the service: `mbopt run` starts a server and
// workers that analyse the double-wishbone suspension kinematically (a
// fully driven spatial scene) by finite differences; the study converges
// with a small fraction of its start's bump steer, and one worker gives
// the same result as two.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/e2e/e2e_harness.h"

namespace mbopt::e2e {
namespace {

// Half the toe range of the starting hardpoints over +-80 mm, deg (the
// objective; SpatialKinematics.SuspensionExampleHoldsItsLinksAndFollowsTheTravel
// measures the range, 6.15 deg, from the scene).
constexpr double kStartHalfRangeDeg = 3.07;

TEST(SuspensionEndToEnd, BumpSteerStudyConvergesThroughMboptRunWithTheSameResultOnOneAndTwoWorkers) {
  const std::string study = std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/suspension/suspension.study.textproto";
  const std::vector<std::string> env = {"MBOPT_SERVER_BIN=" + ServerBinary(), "MBOPT_WORKER_BIN=" + WorkerBinary()};
  auto two = Mbopt({"run", study, "--workers", "2", "--json", "--discard-db"}, env);
  ASSERT_EQ(two.exit_code, 0) << two.stdout_text << two.stderr_text;
  EXPECT_EQ(JsonField(two.stdout_text, "status"), "converged") << two.stdout_text;
  EXPECT_LT(std::stod(JsonField(two.stdout_text, "objective")), 0.01 * kStartHalfRangeDeg) << two.stdout_text;
  auto one = Mbopt({"run", study, "--workers", "1", "--json", "--discard-db"}, env);
  ASSERT_EQ(one.exit_code, 0) << one.stdout_text << one.stderr_text;
  EXPECT_EQ(Comparable(one.stdout_text), Comparable(two.stdout_text));
}

}  // namespace
}  // namespace mbopt::e2e
