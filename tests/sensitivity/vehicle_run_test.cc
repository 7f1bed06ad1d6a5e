// The vehicle study (examples/vehicle) optimized in-process with simulator
// sensitivities and with forward finite differences: same optimum, fewer
// analyses.
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "worker/local_run/local_run.h"
#include "spec/io/study_io.h"

namespace mbopt::local_run {
namespace {

constexpr char kVehicleStudy[] = "examples/vehicle/vehicle.study.textproto";
constexpr double kSameOptimum = 0.005;  // relative, in F (the brief's 0.5 %)
constexpr double kFeasible = 0.005;     // maxg, the convergence tolerance

TEST(SimulatorSensitivityRun, VehicleReachesTheFiniteDifferenceOptimumWithFewerAnalyses) {
  absl::StatusOr<spec::Study> fd_study = spec::io::LoadStudyFile(kVehicleStudy);
  ASSERT_TRUE(fd_study.ok()) << fd_study.status();
  spec::Study sim_study = *fd_study;
  sim_study.optimizer.simulator_sensitivities = true;

  absl::StatusOr<LocalRunResult> fd = RunStudyLocally(*fd_study);
  ASSERT_TRUE(fd.ok()) << fd.status();
  absl::StatusOr<LocalRunResult> sim = RunStudyLocally(sim_study);
  ASSERT_TRUE(sim.ok()) << sim.status();
  std::cout << "finite differences: F = " << fd->outcome.objective << ", maxg = "
            << fd->outcome.max_violation << ", cycles " << fd->outcome.cycles << ", analyses "
            << fd->analyses_run << ", analysis wall " << fd->total_counters.wall_seconds
            << " s (" << fd->total_counters.wall_seconds / fd->analyses_run << " s each)\n"
            << "simulator:          F = " << sim->outcome.objective << ", maxg = "
            << sim->outcome.max_violation << ", cycles " << sim->outcome.cycles << ", analyses "
            << sim->analyses_run << ", analysis wall " << sim->total_counters.wall_seconds
            << " s (" << sim->total_counters.wall_seconds / sim->analyses_run << " s each)\n";
  EXPECT_EQ(fd->outcome.state, slp::RunState::kConverged) << fd->end_reason;
  EXPECT_EQ(sim->outcome.state, slp::RunState::kConverged) << sim->end_reason;
  EXPECT_LT(sim->outcome.max_violation, kFeasible);
  EXPECT_LT(std::abs(sim->outcome.objective - fd->outcome.objective) / std::abs(fd->outcome.objective),
            kSameOptimum);
  EXPECT_LT(sim->analyses_run, fd->analyses_run);
}

}  // namespace
}  // namespace mbopt::local_run
