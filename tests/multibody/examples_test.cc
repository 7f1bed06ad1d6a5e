// The multibody examples (examples/press, examples/isolator) through the
// study loader, the engine and a job: they load, each gets the analysis its
// degrees of freedom call for, and the optimizer reaches the optimum the
// problem predicts. Also the loader's errors for multibody scenes.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/testing/local_run/local_run.h"

namespace mbopt {
namespace {

using ::testing::HasSubstr;

constexpr char kPressStudy[] = "examples/press/press.study.textproto";

TEST(PressStudy, LoadsAndIsAnalysedKinetostatically) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile(kPressStudy);
  ASSERT_TRUE(study.ok()) << study.status();
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(*study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  Eigen::VectorXd x0(2);
  x0 << 1.5, 8.0;
  absl::StatusOr<engine::StudyEvaluation> e = local_run::EvaluateDesign(*study, *layout, x0);
  ASSERT_TRUE(e.ok()) << e.status();
  ASSERT_TRUE(e->ok()) << e->failure.reason;
  EXPECT_EQ(e->formulation, spec::Formulation::kKinetostatic);
  EXPECT_EQ(e->counters.time_steps, 0);       // driven: no time integration
  EXPECT_EQ(e->counters.position_solves, 101);
  // The slider ends at bottom dead centre, l - r = 0.65 m: the reach row is
  // (0.65 - 0.45) / 0.45 over its limit.
  constexpr double kRoundOff = 1e-9;
  EXPECT_NEAR(e->values->max_violation, 0.2 / 0.45, kRoundOff);
}

// Peak torque grows with the crank radius and falls with the rod length;
// the reach limit l - r <= 0.45 m ties them, so the optimum is the smallest
// crank (the stroke's bound, r = 0.1 m) with l = 0.55 m, the obliquity
// (0.1 / 0.55 rad at most) well inside its limit.
// The wall-time limit covers sweeps that do not integrate: a kinetostatic
// press (multibody) and the landing gear's kinematic sweep (linkage), each
// with a limit that is over before the first instant.
TEST(WallTimeLimit, SweepsWithoutAnIntegratorEndAsNamedTimeLimitFailures) {
  struct Case {
    const char* study;
    std::vector<double> x0;
  };
  for (const Case& c : {Case{kPressStudy, {1.5, 8.0}},
                        Case{"examples/landing_gear/landing_gear.study.textproto", {}}}) {
    absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile(c.study);
    ASSERT_TRUE(study.ok()) << study.status();
    EXPECT_EQ(study->scene.integrator.max_wall_seconds, spec::kDefaultAnalysisWallSeconds) << "the default applies";
    study->scene.integrator.max_wall_seconds = 1e-12;
    absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(*study);
    ASSERT_TRUE(layout.ok()) << layout.status();
    Eigen::VectorXd x0(static_cast<Eigen::Index>(study->variables.size()));
    for (size_t i = 0; i < study->variables.size(); ++i) {
      x0[static_cast<Eigen::Index>(i)] = c.x0.empty() ? study->variables[i].initial : c.x0[i];
    }
    absl::StatusOr<engine::StudyEvaluation> e = local_run::EvaluateDesign(*study, *layout, x0);
    ASSERT_TRUE(e.ok()) << e.status();
    EXPECT_FALSE(e->ok()) << c.study;
    EXPECT_EQ(e->failure.kind, spec::FailureKind::kTimeLimit) << c.study << ": " << e->failure.reason;
    EXPECT_THAT(e->failure.reason, HasSubstr("wall-time limit")) << c.study;
  }
}

// Issue 16's hostile values: a parameter of 1e20 or 2147483647 (a
// stiffness, a damping, a mass) ends within the step budget, as a result or
// as a named failure, never as an analysis that runs without end.
TEST(HostileParameters, ExtremeValuesEndWithinTheBudgetsAsResultOrNamedFailure) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("examples/vehicle/vehicle.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(*study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  const Eigen::Index n = static_cast<Eigen::Index>(study->variables.size());
  for (const double extreme : {1e20, 2147483647.0}) {
    for (Eigen::Index i = 0; i < n; ++i) {
      Eigen::VectorXd x(n);
      for (Eigen::Index j = 0; j < n; ++j) x[j] = study->variables[static_cast<size_t>(j)].initial;
      x[i] = extreme / study->variables[static_cast<size_t>(i)].scale;
      absl::StatusOr<engine::StudyEvaluation> e = local_run::EvaluateDesign(*study, *layout, x);
      ASSERT_TRUE(e.ok()) << e.status();
      EXPECT_LE(e->counters.time_steps, study->scene.integrator.max_steps);
      if (!e->ok()) {
        EXPECT_NE(e->failure.kind, spec::FailureKind::kUnclassified) << e->failure.reason;
        EXPECT_FALSE(e->failure.reason.empty());
      }
    }
  }
}

TEST(PressStudy, OptimumIsTheStrokeBoundWithTheReachLimitActive) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile(kPressStudy);
  ASSERT_TRUE(study.ok()) << study.status();
  absl::StatusOr<local_run::LocalRunResult> run = local_run::RunStudyLocally(*study);
  ASSERT_TRUE(run.ok()) << run.status();
  EXPECT_EQ(run->outcome.state, slp::RunState::kConverged) << run->end_reason;
  ASSERT_EQ(run->design_si.size(), 2u);
  // The SLP's convergence tolerance (0.5 % on F, 0.5 % on maxg) bounds how
  // close it stops to the vertex.
  constexpr double kDesignTolerance = 1e-3;  // m
  EXPECT_NEAR(run->design_si[0], 0.10, kDesignTolerance);
  EXPECT_NEAR(run->design_si[1], 0.55, kDesignTolerance);
  EXPECT_LE(run->outcome.max_violation, 0.0);
  std::cout << "press: peak torque " << run->outcome.objective << " N m after " << run->outcome.cycles
            << " cycles, " << run->outcome.analyses << " analyses\n";
}

// A mechanism that moves freely (examples/isolator): forward dynamics with
// IDAS at every analysis, and an optimum where the swing limit is active.
TEST(IsolatorStudy, ConvergesWithTheSwingLimitActive) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("examples/isolator/isolator.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  absl::StatusOr<spec::StudyLayout> layout = spec::MakeStudyLayout(*study);
  ASSERT_TRUE(layout.ok()) << layout.status();
  Eigen::VectorXd x0(2);
  x0 << 20.0, 2.0;
  absl::StatusOr<engine::StudyEvaluation> start = local_run::EvaluateDesign(*study, *layout, x0);
  ASSERT_TRUE(start.ok() && start->ok());
  EXPECT_EQ(start->formulation, spec::Formulation::kDynamic);
  EXPECT_GT(start->counters.time_steps, 0);
  EXPECT_GT(start->values->max_violation, 0.0);  // the start swings too much
  absl::StatusOr<local_run::LocalRunResult> run = local_run::RunStudyLocally(*study);
  ASSERT_TRUE(run.ok()) << run.status();
  EXPECT_EQ(run->outcome.state, slp::RunState::kConverged) << run->end_reason;
  // Active: within the study's convergence tolerance (1e-4) of its limit.
  constexpr double kActive = 1e-4;
  EXPECT_NEAR(run->outcome.max_violation, 0.0, kActive);
  EXPECT_LE(run->outcome.max_violation, 0.0);
  // A feasible design that transmits less than the (infeasible) start's
  // 69.7 N; the preload alone is 36.8 N.
  EXPECT_LT(run->outcome.objective, 65.0);
  EXPECT_GT(run->outcome.objective, 36.8);
  std::cout << "isolator: peak force " << run->outcome.objective << " N at k = " << run->design_si[0]
            << " N/m, c = " << run->design_si[1] << " N s/m after " << run->outcome.cycles << " cycles\n";
}

// Simulator sensitivities (multibody: IDAS forward sensitivities for the
// isolator, the differentiated constraint equations for the press) give
// the optimizer the gradients it would get from finite differences: the
// same optimum, with one analysis per cycle instead of 1 + n.
void ExpectSameOptimumWithFewerAnalyses(const char* path, double design_tolerance) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile(path);
  ASSERT_TRUE(study.ok()) << study.status();
  absl::StatusOr<local_run::LocalRunResult> differences = local_run::RunStudyLocally(*study);
  study->optimizer.simulator_sensitivities = true;
  absl::StatusOr<local_run::LocalRunResult> simulator = local_run::RunStudyLocally(*study);
  ASSERT_TRUE(differences.ok() && simulator.ok());
  EXPECT_EQ(simulator->outcome.state, slp::RunState::kConverged) << simulator->end_reason;
  for (size_t i = 0; i < simulator->design_si.size(); ++i) {
    EXPECT_NEAR(simulator->design_si[i], differences->design_si[i],
                design_tolerance * std::abs(differences->design_si[i]));
  }
  EXPECT_NEAR(simulator->outcome.objective, differences->outcome.objective,
              5e-3 * std::abs(differences->outcome.objective));
  EXPECT_LT(simulator->analyses_run, differences->analyses_run);
  std::cout << path << ": " << simulator->outcome.cycles << " cycles, " << simulator->analyses_run
            << " analyses with simulator sensitivities, F = " << simulator->outcome.objective << "; "
            << differences->outcome.cycles << " cycles, " << differences->analyses_run
            << " analyses with finite differences, F = " << differences->outcome.objective << "\n";
}

TEST(MultibodySensitivityStudies, PressReachesTheSameOptimumWithFewerAnalyses) {
  ExpectSameOptimumWithFewerAnalyses(kPressStudy, 5e-3);
}

TEST(MultibodySensitivityStudies, IsolatorReachesTheSameOptimumWithFewerAnalyses) {
  ExpectSameOptimumWithFewerAnalyses("examples/isolator/isolator.study.textproto", 2e-2);
}

TEST(MultibodySceneLoading, UnknownMarkerIsNamedWithFileLineAndTheMarkersThatExist) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "mbopt_multibody_scene_test";
  std::filesystem::create_directories(dir);
  std::ifstream in("examples/press/press.scene.textproto");
  std::string scene((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string from = "b: \"crank.pivot\"";
  ASSERT_NE(scene.find(from), std::string::npos);
  scene.replace(scene.find(from), from.size(), "b: \"crank.hub\"");
  std::ofstream(dir / "press.scene.textproto") << scene;
  std::ifstream study_in(kPressStudy);
  std::ofstream(dir / "press.study.textproto") << study_in.rdbuf();
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile((dir / "press.study.textproto").string());
  ASSERT_FALSE(study.ok());
  const std::string message(study.status().message());
  EXPECT_THAT(message, HasSubstr("press.scene.textproto:"));
  EXPECT_THAT(message, HasSubstr("multibody.joints[0]"));
  EXPECT_THAT(message, HasSubstr("no marker \"hub\""));
  EXPECT_THAT(message, HasSubstr("pivot, pin"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mbopt
