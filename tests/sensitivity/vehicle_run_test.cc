// The vehicle study (examples/vehicle) optimized in-process with simulator
// sensitivities and with forward finite differences: same optimum, fewer
// analyses.
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "tests/testing/local_run/local_run.h"
#include "spec/io/study_io.h"

namespace mbopt::local_run {
namespace {

constexpr char kVehicleStudy[] = "examples/vehicle/vehicle.study.textproto";
constexpr double kSameOptimum = 0.005;  // relative, in F (the brief's 0.5 %)

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
  EXPECT_LE(sim->outcome.max_violation, 0.0);
  EXPECT_LT(std::abs(sim->outcome.objective - fd->outcome.objective) / std::abs(fd->outcome.objective),
            kSameOptimum);
  EXPECT_LT(sim->analyses_run, fd->analyses_run);
}

// The same comparison for the studies that name their responses and take
// the worst of two terms (examples/vehicle/vehicle_worst_case), and for a
// variable that sets both tyre stiffnesses.
void ExpectSameOptimumWithFewerAnalyses(const spec::Study& fd_study) {
  spec::Study sim_study = fd_study;
  sim_study.optimizer.simulator_sensitivities = true;
  absl::StatusOr<LocalRunResult> fd = RunStudyLocally(fd_study);
  ASSERT_TRUE(fd.ok()) << fd.status();
  absl::StatusOr<LocalRunResult> sim = RunStudyLocally(sim_study);
  ASSERT_TRUE(sim.ok()) << sim.status();
  std::cout << fd_study.name << ": finite differences F = " << fd->outcome.objective << " in " << fd->analyses_run
            << " analyses; simulator F = " << sim->outcome.objective << " in " << sim->analyses_run << "\n";
  EXPECT_EQ(sim->outcome.state, slp::RunState::kConverged) << sim->end_reason;
  EXPECT_LE(sim->outcome.max_violation, 0.0);
  EXPECT_LT(std::abs(sim->outcome.objective - fd->outcome.objective) / std::abs(fd->outcome.objective),
            kSameOptimum);
  EXPECT_LT(sim->analyses_run, fd->analyses_run);
  // Every gradient came from the simulator: one analysis per cycle, and one
  // per restoration step that moved the converged design inside its limits.
  int restoration_analyses = 0;
  for (const slp::CycleRecord& r : sim->outcome.records) {
    if (r.restoration && r.x_trial != r.x0) ++restoration_analyses;
  }
  EXPECT_EQ(sim->analyses_run, sim->outcome.cycles + 1 + restoration_analyses);
}

TEST(SimulatorSensitivityRun, ResponsesAndWorstCaseObjective) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("examples/vehicle/vehicle_worst_case.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  ExpectSameOptimumWithFewerAnalyses(*study);
}

TEST(SimulatorSensitivityRun, TwoLoadCases) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("examples/vehicle/vehicle_two_roads.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  ExpectSameOptimumWithFewerAnalyses(*study);
}

TEST(SimulatorSensitivityRun, VariableSettingBothTyreStiffnesses) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile(kVehicleStudy);
  ASSERT_TRUE(study.ok()) << study.status();
  study->variables[1].also_sets = {study->scene.FindParameter("k3")};
  study->variables.erase(study->variables.begin() + 2);
  ExpectSameOptimumWithFewerAnalyses(*study);
}

}  // namespace
}  // namespace mbopt::local_run
