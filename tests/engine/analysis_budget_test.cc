// One analysis budget for every analysis: a deadline on the caller's clock
// (here a fake one, so that a time limit falls at a known check whatever the
// machine), a step budget (integrator.max_steps, also for sweeps without an
// integrator) and a cancel flag; and the absurd inputs that would run for
// ever, refused or stopped at their limits with a reason naming them.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "spec/io/study_io.h"
#include "tests/testing/fake_clock.h"
#include "worker/budget/analysis_budget.h"
#include "worker/engine/analysis.h"
#include "worker/engine/model_kinds.h"

namespace mbopt::engine {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using mbopt::testing::CancelAfter;
using mbopt::testing::SteppingClock;

spec::Scene LoadScene(const std::string& path) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile(path);
  EXPECT_TRUE(scene.ok()) << scene.status();
  return scene.ok() ? *std::move(scene) : spec::Scene();
}

// The slider-crank press: a driven mechanism, analysed kinetostatically
// (no integrator: a sweep of position solves).
spec::Scene Press() { return LoadScene("examples/press/press.scene.textproto"); }
// The vehicle: a lumped scene integrated by CVODES.
spec::Scene Vehicle() {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("examples/vehicle/vehicle.study.textproto");
  EXPECT_TRUE(study.ok()) << study.status();
  return study.ok() ? study->scene : spec::Scene();
}
// The isolator: a multibody scene with a free degree of freedom, integrated
// by IDAS.
spec::Scene Isolator() { return LoadScene("examples/isolator/isolator.scene.textproto"); }

// A bar on a torsion spring, balanced by static equilibrium (KINSOL) at
// every instant of its grid.
spec::Scene StaticArm() {
  absl::StatusOr<spec::Scene> scene = spec::io::ParseSceneText(R"pb(
    name: "arm"
    parameters { name: "k" value: 20 }
    effects { gravity { acceleration_m_per_s2 { x { value: 0 } y { value: -9.81 } } } }
    multibody {
      analysis: MULTIBODY_ANALYSIS_STATIC_EQUILIBRIUM
      ground_markers { name: "origin" }
      bodies {
        name: "arm"
        mass_kg { value: 2 }
        inertia_kg_m2 { value: 0.1067 }
        position_m { x { value: 0.4 } }
        markers { name: "pin" position_m { x { value: -0.4 } } }
      }
      joints { name: "pin" kind: JOINT_REVOLUTE a: "ground.origin" b: "arm.pin" }
      rotational_springs { name: "spring" joint: "pin" stiffness_n_m_per_rad { param: "k" } }
    }
    outputs { name: "angle" joint_coordinate { joint: "pin" } }
    time_grid { start_s: 0 end_s: 1 points: 11 }
  )pb",
                                                                  "static_arm");
  EXPECT_TRUE(scene.ok()) << scene.status();
  return scene.ok() ? *std::move(scene) : spec::Scene();
}

// A budget on a clock that moves 1 s per reading, no cancel flag.
budget::AnalysisBudget OnSteppingClock(const SteppingClock& clock) {
  return budget::AnalysisBudget(clock.AsClock(), nullptr);
}

TEST(AnalysisBudget, WithoutAClockThereIsNoDeadlineAndNoWallTime) {
  const budget::AnalysisBudget none = budget::AnalysisBudget().ForAnalysis(1e-9, 0);
  EXPECT_FALSE(none.has_deadline());
  EXPECT_TRUE(none.Check(0.0).ok());
  EXPECT_EQ(none.NowSeconds(), 0.0);
}

TEST(AnalysisBudget, DeadlineIsTheEarlierOfTheCallersAndTheScenes) {
  const SteppingClock clock(1.0);
  const budget::AnalysisBudget caller = OnSteppingClock(clock).ForAnalysis(5.0, 0);  // reading 1: deadline 6
  const budget::AnalysisBudget scene = caller.ForAnalysis(100.0, 0);  // reading 2: 102 is later, 6 stays
  EXPECT_TRUE(scene.Check(1.0).ok());                                  // reading 3
  EXPECT_TRUE(scene.Check(1.0).ok());
  EXPECT_TRUE(scene.Check(1.0).ok());
  const spec::AnalysisFailure at_deadline = scene.Check(2.5);  // reading 6 is not past 6; 7 is
  EXPECT_TRUE(at_deadline.ok());
  const spec::AnalysisFailure late = scene.Check(2.5);
  EXPECT_EQ(late.kind, spec::FailureKind::kTimeLimit);
  EXPECT_THAT(late.reason, AllOf(HasSubstr("wall-time limit of 5 s"), HasSubstr("t = 2.5 s")));
}

TEST(AnalysisBudget, StepsAreCountedPerAnalysis) {
  budget::AnalysisBudget caller;
  budget::AnalysisBudget first = caller.ForAnalysis(0.0, 3);
  EXPECT_TRUE(first.ChargeSteps(3, 0.0).ok());
  const spec::AnalysisFailure spent = first.ChargeSteps(1, 0.25);
  EXPECT_EQ(spent.kind, spec::FailureKind::kTimeLimit);
  EXPECT_THAT(spent.reason, AllOf(HasSubstr("step budget of 3 steps (integrator.max_steps)"), HasSubstr("0.25")));
  budget::AnalysisBudget second = caller.ForAnalysis(0.0, 3);
  EXPECT_TRUE(second.ChargeSteps(3, 0.0).ok()) << "a new analysis starts with its whole budget";
}

TEST(AnalysisBudget, CancelComesBeforeTheDeadline) {
  const SteppingClock clock(1000.0);
  const CancelAfter cancel(1);
  const budget::AnalysisBudget budget = budget::AnalysisBudget(clock.AsClock(), cancel.AsFlag()).ForAnalysis(1.0, 0);
  const spec::AnalysisFailure f = budget.Check(0.5);
  EXPECT_EQ(f.kind, spec::FailureKind::kCancelled);
  EXPECT_STREQ(spec::FailureKindName(f.kind), "cancelled");
}

// The engine reads only the caller's clock: the wall time it reports is
// what that clock says, here a whole number of readings.
TEST(EngineBudget, WallTimeIsReadOnTheCallersClock) {
  const spec::Scene scene = Press();
  const SteppingClock clock(1.0);
  const spec::AnalysisReport with_clock =
      Analyze(scene, scene.DefaultParameterValues(), nullptr, OnSteppingClock(clock));
  ASSERT_TRUE(with_clock.ok()) << with_clock.failure.reason;
  // One reading sets the deadline, the next starts the wall time, the last
  // ends it.
  EXPECT_EQ(with_clock.counters.wall_seconds, static_cast<double>(clock.reads() - 2));
  EXPECT_GT(clock.reads(), 101) << "the sweep checks the clock at every instant";
  const spec::AnalysisReport without = Analyze(scene, scene.DefaultParameterValues());
  ASSERT_TRUE(without.ok()) << without.failure.reason;
  EXPECT_EQ(without.counters.wall_seconds, 0.0) << "no clock, no wall time";
  EXPECT_EQ(without.outputs[0].series[0], with_clock.outputs[0].series[0]) << "the clock changes no result";
}

TEST(EngineBudget, LumpedSceneEndsAtItsWallTimeLimit) {
  spec::Scene scene = Vehicle();
  scene.integrator.max_wall_seconds = 50.0;
  const SteppingClock clock(1.0);
  const spec::AnalysisReport r =
      Analyze(scene, scene.DefaultParameterValues(), nullptr, OnSteppingClock(clock));
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kTimeLimit) << r.failure.reason;
  EXPECT_THAT(r.failure.reason, HasSubstr("wall-time limit of 50 s (integrator.max_wall_seconds)"));
  EXPECT_LE(r.counters.rhs_evaluations, 52);
}

TEST(EngineBudget, LumpedSceneStopsWhenCancelled) {
  const spec::Scene scene = Vehicle();
  const CancelAfter cancel(20);
  const spec::AnalysisReport r =
      Analyze(scene, scene.DefaultParameterValues(), nullptr, budget::AnalysisBudget(nullptr, cancel.AsFlag()));
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kCancelled) << r.failure.reason;
  EXPECT_LE(r.counters.rhs_evaluations, 20);
}

TEST(EngineBudget, KinematicSweepEndsAtItsWallTimeLimit) {
  spec::Scene scene = Press();
  scene.integrator.max_wall_seconds = 30.0;
  const SteppingClock clock(1.0);
  const spec::AnalysisReport r =
      Analyze(scene, scene.DefaultParameterValues(), nullptr, OnSteppingClock(clock));
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kTimeLimit) << r.failure.reason;
  EXPECT_THAT(r.failure.reason, HasSubstr("wall-time limit of 30 s"));
  EXPECT_LT(r.counters.position_solves, 30);
}

// integrator.max_steps also bounds the position solves of a sweep: the
// press's 101 instants do not fit in 50.
TEST(EngineBudget, KinematicSweepEndsAtItsStepBudget) {
  spec::Scene scene = Press();
  scene.integrator.max_steps = 50;
  const spec::AnalysisReport r = Analyze(scene, scene.DefaultParameterValues());
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kTimeLimit) << r.failure.reason;
  EXPECT_THAT(r.failure.reason, HasSubstr("step budget of 50 steps (integrator.max_steps)"));
  EXPECT_EQ(r.counters.position_solves, 50);
}

TEST(EngineBudget, KinematicSweepStopsWhenCancelled) {
  const spec::Scene scene = Press();
  const CancelAfter cancel(10);
  const spec::AnalysisReport r =
      Analyze(scene, scene.DefaultParameterValues(), nullptr, budget::AnalysisBudget(nullptr, cancel.AsFlag()));
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kCancelled) << r.failure.reason;
  EXPECT_LT(r.counters.position_solves, 10);
}

TEST(EngineBudget, StaticSweepEndsAtItsStepBudgetAndWhenCancelled) {
  spec::Scene scene = StaticArm();
  const spec::AnalysisReport whole = Analyze(scene, {20.0});
  ASSERT_TRUE(whole.ok()) << whole.failure.reason;
  EXPECT_EQ(whole.counters.position_solves, 11);
  scene.integrator.max_steps = 4;
  const spec::AnalysisReport short_budget = Analyze(scene, {20.0});
  EXPECT_EQ(short_budget.failure.kind, spec::FailureKind::kTimeLimit) << short_budget.failure.reason;
  EXPECT_THAT(short_budget.failure.reason, HasSubstr("step budget of 4 steps"));
  const CancelAfter cancel(3);
  const spec::AnalysisReport cancelled =
      Analyze(StaticArm(), {20.0}, nullptr, budget::AnalysisBudget(nullptr, cancel.AsFlag()));
  EXPECT_EQ(cancelled.failure.kind, spec::FailureKind::kCancelled) << cancelled.failure.reason;
}

TEST(EngineBudget, ForwardDynamicsEndsAtItsWallTimeLimitAndWhenCancelled) {
  spec::Scene scene = Isolator();
  scene.integrator.max_wall_seconds = 40.0;
  const SteppingClock clock(1.0);
  const spec::AnalysisReport timed =
      Analyze(scene, scene.DefaultParameterValues(), nullptr, OnSteppingClock(clock));
  EXPECT_EQ(timed.failure.kind, spec::FailureKind::kTimeLimit) << timed.failure.reason;
  EXPECT_THAT(timed.failure.reason, HasSubstr("wall-time limit of 40 s"));
  EXPECT_GT(timed.counters.rhs_evaluations, 0) << "stopped in the integration, not before";
  const CancelAfter cancel(25);
  const spec::AnalysisReport cancelled =
      Analyze(Isolator(), scene.DefaultParameterValues(), nullptr, budget::AnalysisBudget(nullptr, cancel.AsFlag()));
  EXPECT_EQ(cancelled.failure.kind, spec::FailureKind::kCancelled) << cancelled.failure.reason;
  EXPECT_LE(cancelled.counters.rhs_evaluations, 25);
}

// A crank at 1e29 rad/s turns about 1.6e26 times between two of the press's
// instants 10 ms apart: no analysis follows that (and the positions would
// be round-off). Refused before anything is solved, naming the driver and
// the figure.
TEST(AbsurdInputs, CrankTooFastForTheStepBudgetIsAnInvalidModel) {
  spec::Scene scene = Press();
  auto& drivers = std::get<spec::MultibodyModel>(scene.model).drivers;
  ASSERT_EQ(drivers.size(), 1u);
  drivers[0].rate = spec::Number{1e29, -1, nullptr};
  const spec::AnalysisReport r = Analyze(scene, scene.DefaultParameterValues());
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kInvalidModel) << r.failure.reason;
  EXPECT_THAT(r.failure.reason, AllOf(HasSubstr("driver of joint 'main'"), HasSubstr("1.59e+26 times"),
                                      HasSubstr("integrator.max_steps")));
  EXPECT_EQ(r.counters.position_solves, 0);
}

// The press's crank at its own rate over a grid that ends at 1e20 s: 1e18 s
// between instants.
TEST(AbsurdInputs, TimeGridThatEndsAt1e20SecondsIsAnInvalidModelForADrivenCrank) {
  spec::Scene scene = Press();
  scene.time_grid.end_s = 1e20;
  const spec::AnalysisReport r = Analyze(scene, scene.DefaultParameterValues());
  EXPECT_EQ(r.failure.kind, spec::FailureKind::kInvalidModel) << r.failure.reason;
  EXPECT_THAT(r.failure.reason, AllOf(HasSubstr("driver of joint 'main'"), HasSubstr("times between t = 0 s")));
}

// The isolator's shaker moves a prismatic joint (no turns to count): its
// integration over 1e20 s, following the shaking, ends at the step budget
// or the time limit, whichever comes first, not after 1e20 s of shaking.
TEST(AbsurdInputs, TimeGridThatEndsAt1e20SecondsEndsAtALimitForForwardDynamics) {
  spec::Scene scene = Isolator();
  scene.time_grid.end_s = 1e20;
  scene.integrator.max_steps = 2000;
  scene.integrator.max_wall_seconds = 1000.0;
  const SteppingClock clock(0.001);  // 1 ms per reading: 1e6 readings before the limit
  const spec::AnalysisReport r =
      Analyze(scene, scene.DefaultParameterValues(), nullptr, OnSteppingClock(clock));
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(r.failure.kind == spec::FailureKind::kIntegrator || r.failure.kind == spec::FailureKind::kTimeLimit)
      << spec::FailureKindName(r.failure.kind) << ": " << r.failure.reason;
  EXPECT_LE(r.counters.time_steps, 2001);
}

// Every model kind has an entry, each saying what it counts; and only the
// kinds that have them claim simulator sensitivities.
TEST(ModelKinds, EveryKindHasItsEntry) {
  std::vector<std::string> names;
  for (const ModelKind& kind : ModelKinds()) {
    ASSERT_NE(kind.name, nullptr);
    names.push_back(kind.name);
    EXPECT_NE(kind.analyze, nullptr) << kind.name;
    EXPECT_NE(std::string(kind.counters), "") << kind.name;
    EXPECT_NE(std::string(kind.analysis), "") << kind.name;
  }
  EXPECT_THAT(names, ::testing::UnorderedElementsAre("lumped", "linkage", "multibody", "external", "fmu", "spatial"));
  EXPECT_STREQ(ModelKindOf(Vehicle()).name, "lumped");
  EXPECT_STREQ(ModelKindOf(Press()).name, "multibody");
  for (const ModelKind& kind : ModelKinds()) {
    const std::string why = kind.sensitivities_unavailable(Vehicle(), {0});
    if (kind.analyze_with_sensitivities == nullptr) {
      EXPECT_NE(why, "") << kind.name << " must say why not";
    }
  }
}

}  // namespace
}  // namespace mbopt::engine
