// examples/fmu's study optimized in this process (local_run: the service's
// job code with the engine in-process), against its closed-form optimum.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "spec/io/study_io.h"
#include "tests/fmu/closed_forms.h"
#include "tests/testing/temp_dir.h"
#include "tests/testing/local_run/local_run.h"

namespace mbopt::fmu {
namespace {

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The example's files in a fresh folder, the scene naming this build's FMU
// (the example names it in the default build folder).
std::string CopyExample(const std::filesystem::path& folder) {
  std::string scene = ReadFile("examples/fmu/oscillator.scene.textproto");
  const std::string relative = "../../build/tests/fmu/archives/damped_oscillator.fmu";
  const std::size_t at = scene.find(relative);
  EXPECT_NE(at, std::string::npos);
  scene.replace(at, relative.size(), testing::TestFmu("damped_oscillator"));
  std::ofstream(folder / "oscillator.scene.textproto") << scene;
  std::ofstream(folder / "oscillator.study.textproto") << ReadFile("examples/fmu/oscillator.study.textproto");
  return (folder / "oscillator.study.textproto").string();
}

TEST(FmuStudy, OscillatorExampleReachesItsClosedFormOptimum) {
  const ::mbopt::testing::TempDir dir;
  auto study = spec::io::LoadStudyFile(CopyExample(dir.path()));
  ASSERT_TRUE(study.ok()) << study.status();
  auto run = local_run::RunStudyLocally(*study);
  ASSERT_TRUE(run.ok()) << run.status();
  EXPECT_EQ(run->outcome.state, slp::RunState::kConverged) << run->end_reason;
  ASSERT_EQ(run->design_si.size(), 2u);
  // The optimum from the closed form on the 10 ms grid (bisection on k,
  // golden section on c): k = 1.355513 N/m, c = 1.376517 N s/m. The run's
  // convergence tolerances are 1e-4; it ends on the vertex of the two active
  // rows, so 2e-4 leaves room for an optimizer change that still converges.
  EXPECT_NEAR(run->design_si[0], 1.355513, 2e-4);
  EXPECT_NEAR(run->design_si[1], 1.376517, 2e-4);
  // The reported design settles: |x| <= 1 cm from 2 s on (closed form).
  const testing::DampedOscillator design{1.0, run->design_si[1], run->design_si[0], 0.1};
  double worst_m = 0.0;
  for (int i = 200; i <= 400; ++i) worst_m = std::max(worst_m, std::abs(design.X(0.01 * i)));
  EXPECT_LE(worst_m, 0.01 * (1.0 + 1e-6));
  EXPECT_EQ(run->analyses_failed, 0);
}

// The same study with SENSITIVITY_METHOD_SIMULATOR: the oscillator FMU
// provides directional derivatives, so the gradients come from CVODES'
// forward sensitivities, one analysis per design instead of 1 + 2.
TEST(FmuStudy, SimulatorSensitivitiesReachTheSameOptimumWithFewerAnalyses) {
  const ::mbopt::testing::TempDir dir;
  const std::string path = CopyExample(dir.path());
  std::string text = ReadFile(path);
  const std::size_t at = text.find("optimizer { ");
  ASSERT_NE(at, std::string::npos);
  text.insert(at + 12, "sensitivity: SENSITIVITY_METHOD_SIMULATOR ");
  std::ofstream(path) << text;
  auto study = spec::io::LoadStudyFile(path);
  ASSERT_TRUE(study.ok()) << study.status();
  ASSERT_TRUE(study->optimizer.simulator_sensitivities);
  auto simulator = local_run::RunStudyLocally(*study);
  study->optimizer.simulator_sensitivities = false;
  auto differences = local_run::RunStudyLocally(*study);
  ASSERT_TRUE(simulator.ok()) << simulator.status();
  ASSERT_TRUE(differences.ok()) << differences.status();
  EXPECT_EQ(simulator->outcome.state, slp::RunState::kConverged) << simulator->end_reason;
  ASSERT_EQ(simulator->design_si.size(), 2u);
  EXPECT_NEAR(simulator->design_si[0], 1.355513, 2e-4);
  EXPECT_NEAR(simulator->design_si[1], 1.376517, 2e-4);
  EXPECT_EQ(simulator->analyses_failed, 0);
  EXPECT_LT(simulator->analyses_run, differences->analyses_run);
  std::cout << "FMU oscillator: " << simulator->outcome.cycles << " cycles, " << simulator->analyses_run
            << " analyses, " << simulator->wall_seconds << " s with simulator sensitivities; "
            << differences->outcome.cycles << " cycles, " << differences->analyses_run << " analyses, "
            << differences->wall_seconds << " s with finite differences\n";
}

}  // namespace
}  // namespace mbopt::fmu
