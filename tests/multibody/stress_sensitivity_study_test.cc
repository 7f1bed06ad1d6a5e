// A study with a bending-stress constraint (tests/multibody/
// propped_cantilever.study.textproto) run to its optimum twice: with
// finite differences and with simulator sensitivities. The stress rows now
// take the simulator's gradients, so the second run needs no perturbed
// analyses (measured: 7 analyses in 5 cycles, against 17), and both reach
// the same design.
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/testing/local_run/local_run.h"

namespace mbopt {
namespace {

TEST(StressSensitivityStudy, StressConstraintTakesSimulatorGradientsToTheSameOptimum) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("tests/multibody/propped_cantilever.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  ASSERT_FALSE(study->optimizer.simulator_sensitivities);
  absl::StatusOr<local_run::LocalRunResult> differences = local_run::RunStudyLocally(*study);
  study->optimizer.simulator_sensitivities = true;
  absl::StatusOr<local_run::LocalRunResult> simulator = local_run::RunStudyLocally(*study);
  ASSERT_TRUE(differences.ok()) << differences.status();
  ASSERT_TRUE(simulator.ok()) << simulator.status();
  EXPECT_EQ(differences->outcome.state, slp::RunState::kConverged) << differences->end_reason;
  EXPECT_EQ(simulator->outcome.state, slp::RunState::kConverged) << simulator->end_reason;
  // Fewer analyses only if every value, the stress rows included, took
  // the simulator's gradients (else the worker differences them all).
  EXPECT_LT(simulator->analyses_run, differences->analyses_run);
  for (size_t i = 0; i < simulator->design_si.size(); ++i) {
    EXPECT_NEAR(simulator->design_si[i], differences->design_si[i], 1e-3 * std::abs(differences->design_si[i]))
        << study->variables[i].name;
  }
  EXPECT_NEAR(simulator->outcome.objective, differences->outcome.objective,
              1e-3 * std::abs(differences->outcome.objective));
  // The largest area, and the stress limit active (within the study's
  // convergence tolerance).
  EXPECT_NEAR(simulator->design_si[1], 1e-4, 1e-9);
  EXPECT_NEAR(simulator->outcome.max_violation, 0.0, 1e-4);
  // Linear theory puts the prop at 651 N/m; the rod's tip shortening and
  // rotation move it by little.
  EXPECT_NEAR(simulator->design_si[0], 651.0, 0.02 * 651.0);
  std::cout << "simulator: " << simulator->outcome.cycles << " cycles, " << simulator->analyses_run
            << " analyses, k = " << simulator->design_si[0] << " N/m, A = " << simulator->design_si[1]
            << " m^2, F = " << simulator->outcome.objective << " N; differences: " << differences->outcome.cycles
            << " cycles, " << differences->analyses_run << " analyses, k = " << differences->design_si[0]
            << " N/m, F = " << differences->outcome.objective << " N\n";
}

}  // namespace
}  // namespace mbopt
