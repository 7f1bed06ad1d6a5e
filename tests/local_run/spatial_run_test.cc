// examples/spatial/governor.study.textproto optimized in this process (the
// service's job driver with an in-process evaluator): finite differences of
// spatial forward-dynamics analyses reach the optimum the study describes,
// the shortest arm and the spring that puts the flyweight on its radius
// limit.
#include <cmath>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/testing/local_run/local_run.h"

namespace mbopt::local_run {
namespace {

TEST(RunStudyLocally, SpatialGovernorTakesTheShortestArmAndTheSpringOnTheLimit) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("examples/spatial/governor.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  absl::StatusOr<LocalRunResult> result = RunStudyLocally(*study);
  ASSERT_TRUE(result.ok()) << result.status();
  const RunOutcome& run = result->outcome;
  EXPECT_EQ(run.state, slp::RunState::kConverged) << slp::RunStateName(run.state) << " " << result->end_reason;
  // On the limit: the radius constraint active, within 1e-4 of it.
  EXPECT_LE(std::abs(run.max_violation), 1e-4);
  ASSERT_EQ(result->design_physical.size(), 2u);
  // The arm at its lower bound, 60 mm; the stiffness far below the start's
  // 200 N/m (a softer spring lets the flyweight out to the limit): 31.5
  // N/m when this was written, in 9 cycles and 29 analyses.
  EXPECT_NEAR(result->design_physical[1], 60.0, 1e-3);
  EXPECT_GT(result->design_physical[0], 10.0);
  EXPECT_LT(result->design_physical[0], 100.0);
  std::cout << "governor: state " << slp::RunStateName(run.state) << " k " << result->design_physical[0]
            << " N/m, arm " << result->design_physical[1] << " mm, maxg " << run.max_violation << ", cycles "
            << run.cycles << ", analyses " << run.analyses << ", wall " << result->wall_seconds << " s\n";
}

}  // namespace
}  // namespace mbopt::local_run
