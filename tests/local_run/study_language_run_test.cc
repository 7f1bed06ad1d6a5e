// Studies that use the study language's equality bands and feasibility
// problems, run to their end with the in-process driver on the carrier
// scene (tests/spec/oscillator_scene.h), whose free parameters u and v make
// the problem closed-form: the answers are known without the optimizer.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/local_run/carrier_study_fixture.h"
#include "tests/spec/oscillator_scene.h"
#include "tests/testing/local_run/local_run.h"

namespace mbopt::local_run {
namespace {

using ::mbopt::testing::CarrierScene;

// The point of the circle u^2 + v^2 = r^2 nearest to (3, 1): (3, 1) r /
// sqrt(10), at squared distance (sqrt(10) - r)^2.
double NearestDistanceSquared(double r) { return (std::sqrt(10.0) - r) * (std::sqrt(10.0) - r); }

// Minimize the squared distance to (3, 1) on a circle written as an
// equality `equals: <value> tolerance: <band>` on a response of u and v.
std::string CircleStudy(const std::string& circle_expr, double equals, double tolerance) {
  return R"pb(name: "nearest point of a circle"
scene_file: "carrier.scene.textproto"
variables { name: "u" parameter: "u" lower: -3 upper: 3 }
variables { name: "v" parameter: "v" lower: -3 upper: 3 }
responses { name: "distance2" expr: "(u - 3)^2 + (v - 1)^2" }
responses { name: "circle" expr: ")pb" +
         circle_expr + R"pb(" }
objective { minimize: "distance2" }
constraints { name: "on_circle" output: "circle" reduction: REDUCTION_FINAL equals: )pb" +
         std::to_string(equals) + " tolerance: " + std::to_string(tolerance) + " }\n";
}

class StudyLanguageRun : public ::mbopt::testing::CarrierStudyTest {
 protected:
  // Runs the circle study whose equality `circle` = `equals` +- `tolerance`
  // holds on the circle of `radius`: converged, inside the band as written
  // (the rows hold its middle half, and a converged design may keep a
  // violation of the outer quarter), every row met, at the nearest point.
  void ExpectConvergesInsideTheBand(const std::string& circle, double equals, double tolerance, double radius) {
    absl::StatusOr<spec::Study> study = Load(CircleStudy(circle, equals, tolerance));
    ASSERT_TRUE(study.ok()) << study.status();
    absl::StatusOr<LocalRunResult> result = RunStudyLocally(*study, LocalRunOptions{});
    ASSERT_TRUE(result.ok()) << result.status();
    const RunOutcome& run = result->outcome;
    EXPECT_EQ(run.state, slp::RunState::kConverged) << slp::RunStateName(run.state) << " " << result->end_reason;
    const double u = run.design[0], v = run.design[1];
    EXPECT_LE(std::abs(u * u + v * v - radius * radius), tolerance) << "u " << u << " v " << v;
    EXPECT_LE(run.max_violation, 0.0);
    EXPECT_NEAR(run.objective, NearestDistanceSquared(radius), 1e-3);
    std::cout << circle << " = " << equals << " +- " << tolerance << ": F " << run.objective << " maxg "
              << run.max_violation << " cycles " << run.cycles << " analyses " << run.analyses << "\n";
  }
};

// A band of 1e-5 around 0 (the circle written u^2 + v^2 - 1 = 0): the rows
// are scaled by the quantity's size, not by the band, so the first trial is
// not 300,000 band widths over and the run ends converged with its design
// inside the band.
TEST_F(StudyLanguageRun, NarrowEqualityBandAroundZeroConvergesInsideTheBand) {
  ExpectConvergesInsideTheBand("u^2 + v^2 - 1", 0.0, 1e-5, 1.0);
}

// A band of 1e-5 of the value (u^2 + v^2 = 4 +- 4e-5).
TEST_F(StudyLanguageRun, EqualityBandOfAHundredThousandthOfItsValueConvergesInsideTheBand) {
  ExpectConvergesInsideTheBand("u^2 + v^2", 4.0, 4e-5, 2.0);
}

// No objective: find u, v on the unit circle (`equals: 1` with its default
// band, 1e-4) with u - v >= 0.5 and v >= 0.2. The start (0.5, 2) meets
// neither; the run ends, converged, at the first accepted design that
// meets both, with F = 0 throughout.
TEST_F(StudyLanguageRun, StudyWithoutAnObjectiveEndsAtTheFirstFeasibleDesign) {
  absl::StatusOr<spec::Study> study = Load(R"pb(name: "feasible point"
scene_file: "carrier.scene.textproto"
variables { name: "u" parameter: "u" lower: -3 upper: 3 }
variables { name: "v" parameter: "v" lower: -3 upper: 3 }
responses { name: "radius2" expr: "u^2 + v^2" }
responses { name: "u_minus_v" expr: "u - v" }
responses { name: "v_value" expr: "v" }
constraints { name: "on_circle" output: "radius2" reduction: REDUCTION_FINAL equals: 1 }
constraints { name: "apart" output: "u_minus_v" reduction: REDUCTION_FINAL lower: 0.5 }
constraints { name: "above" output: "v_value" reduction: REDUCTION_FINAL lower: 0.2 }
)pb");
  ASSERT_TRUE(study.ok()) << study.status();
  int records = 0;
  LocalRunOptions options;
  options.on_record = [&records](const slp::CycleRecord&) { ++records; };
  absl::StatusOr<LocalRunResult> result = RunStudyLocally(*study, options);
  ASSERT_TRUE(result.ok()) << result.status();
  const RunOutcome& run = result->outcome;
  EXPECT_EQ(run.state, slp::RunState::kConverged) << slp::RunStateName(run.state) << " " << result->end_reason;
  EXPECT_EQ(run.objective, 0.0);
  EXPECT_LE(run.max_violation, 0.0);
  const double u = run.design[0], v = run.design[1];
  EXPECT_LE(std::abs(u * u + v * v - 1.0), 1e-4) << "u " << u << " v " << v;
  EXPECT_GE(u - v, 0.5);
  EXPECT_GE(v, 0.2);
  // It stops at the first design that meets them: the last cycle is the
  // one that reached it.
  EXPECT_LT(run.cycles, 20);
  std::cout << "feasible point: u " << u << " v " << v << " maxg " << run.max_violation << " cycles " << run.cycles
            << " analyses " << run.analyses << "\n";
}

// max_t (u - t)^2 + 2 max_t (v - 2t)^2 over t in [0, 1] is least at u =
// 0.5, v = 1: F = 0.25 + 2 * 1 = 2.25. Runs the study and checks that.
void ExpectSumOfPeaksOptimum(const absl::StatusOr<spec::Study>& study, const char* label, double design_tolerance) {
  ASSERT_TRUE(study.ok()) << study.status();
  absl::StatusOr<LocalRunResult> result = RunStudyLocally(*study, LocalRunOptions{});
  ASSERT_TRUE(result.ok()) << result.status();
  const RunOutcome& run = result->outcome;
  EXPECT_EQ(run.state, slp::RunState::kConverged) << slp::RunStateName(run.state) << " " << result->end_reason;
  EXPECT_NEAR(run.objective, 2.25, 1e-5);
  EXPECT_NEAR(run.design[0], 0.5, design_tolerance);
  EXPECT_NEAR(run.design[1], 1.0, design_tolerance);
  EXPECT_LE(run.max_violation, 0.0);
  std::cout << label << ": F " << run.objective << " at u " << run.design[0] << " v " << run.design[1] << " cycles "
            << run.cycles << " analyses " << run.analyses << "\n";
}

// A sum of peaks written as docs/study.md says ("A sum of peaks"), with a
// bound parameter per peak: minimize max_t (u - t)^2 + 2 max_t (v - 2t)^2
// over t in [0, 1]. The peaks are max(u^2, (u - 1)^2) and max(v^2,
// (v - 2)^2), least at u = 0.5 and v = 1: F = 0.25 + 2 * 1 = 2.25.
TEST_F(StudyLanguageRun, SumOfPeaksWrittenWithBoundParametersReachesTheClosedForm) {
  std::string scene = CarrierScene();
  const std::string after = "parameters { name: \"v\" value: 2 }\n";
  scene.insert(scene.find(after) + after.size(), "parameters { name: \"p1\" value: 1 }\nparameters { name: \"p2\" value: 5 }\n");
  std::ofstream(dir_ / "carrier.scene.textproto") << scene;
  absl::StatusOr<spec::Study> study = Load(R"pb(name: "sum of peaks"
scene_file: "carrier.scene.textproto"
variables { name: "u" parameter: "u" initial: 0.9 lower: -2 upper: 2 }
variables { name: "v" parameter: "v" lower: -3 upper: 3 }
variables { name: "p1" parameter: "p1" lower: 0 upper: 10 }
variables { name: "p2" parameter: "p2" lower: 0 upper: 20 }
responses { name: "f1" expr: "(u - t)^2" }
responses { name: "f2" expr: "(v - 2 * t)^2" }
responses { name: "over1" expr: "f1 - p1" }
responses { name: "over2" expr: "f2 - p2" }
responses { name: "peak1" expr: "p1" }
responses { name: "peak2" expr: "p2" }
constraints { name: "bound1" output: "over1" reduction: REDUCTION_MAX limit: 0 }
constraints { name: "bound2" output: "over2" reduction: REDUCTION_MAX limit: 0 }
objective { minimize_sum { terms { output: "peak1" } terms { output: "peak2" weight: 2 } } }
optimizer { convergence_objective_tolerance: 1e-6 max_cycles: 200 }
)pb");
  ExpectSumOfPeaksOptimum(study, "sum of peaks", 1e-4);
}

// The same sum of peaks written directly: REDUCTION_MAX terms in
// minimize_sum (one bound variable per peak inside the optimizer), and the
// second peak as the smallest of -f2 with a negative weight. Two design
// variables instead of four, the same closed form.
TEST_F(StudyLanguageRun, SumOfPeaksWrittenDirectlyReachesTheClosedForm) {
  std::ofstream(dir_ / "carrier.scene.textproto") << CarrierScene();
  absl::StatusOr<spec::Study> study = Load(R"pb(name: "sum of peaks, direct"
scene_file: "carrier.scene.textproto"
variables { name: "u" parameter: "u" initial: 0.9 lower: -2 upper: 2 }
variables { name: "v" parameter: "v" lower: -3 upper: 3 }
responses { name: "f1" expr: "(u - t)^2" }
responses { name: "minus_f2" expr: "-(v - 2 * t)^2" }
objective { minimize_sum { terms { output: "f1" reduction: REDUCTION_MAX }
                           terms { output: "minus_f2" reduction: REDUCTION_MIN weight: -2 } } }
optimizer { convergence_objective_tolerance: 1e-6 max_cycles: 200 }
)pb");
  ExpectSumOfPeaksOptimum(study, "sum of peaks, direct", 1e-3);
}

}  // namespace
}  // namespace mbopt::local_run
