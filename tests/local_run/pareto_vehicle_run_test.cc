// The vehicle's comfort-against-seat-travel front
// (examples/vehicle/vehicle_pareto.study.textproto) run in process, and one
// of its points made again by a separate single run: the ride-comfort study
// with the point's level written as the ordinary limit of s1.
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "server/jobs/job.h"
#include "server/jobs/record_codec.h"
#include "server/lp/make_clp_lp_solver.h"
#include "spec/io/study_io.h"
#include "spec/pareto.h"
#include "tests/testing/local_run/in_process_evaluator.h"
#include "tests/testing/local_run/local_run.h"

namespace mbopt::local_run {
namespace {

constexpr int kPoints = 5;
// A point's run and the single run start from different designs (the
// neighbour's result, the study's initial design) and each stops at the
// method's relative objective tolerance (0.005, docs/method.md section 3):
// they agree to that tolerance.
constexpr double kSameOptimumRelative = 5e-3;

std::vector<slp::CycleRecord> RunFront(const spec::Study& study) {
  absl::StatusOr<std::unique_ptr<jobs::Job>> job =
      jobs::Job::Create(std::make_shared<const spec::Study>(study), [] { return lp::MakeClpLpSolver(); });
  EXPECT_TRUE(job.ok()) << job.status();
  if (!job.ok()) return {};
  InProcessEvaluator evaluator((*job)->study(), (*job)->layout());
  std::vector<slp::CycleRecord> records;
  jobs::JobRunOptions options;
  // The points' records (their runs' cycles come before each).
  options.on_record = [&records](const slp::CycleRecord& r) {
    if (r.pareto) records.push_back(r);
  };
  const absl::Status ran = (*job)->Run(evaluator, options);
  EXPECT_TRUE(ran.ok()) << ran;
  EXPECT_EQ((*job)->state(), jobs::JobState::kCompleted);
  return records;
}

TEST(VehicleParetoFront, TradesComfortAgainstSeatTravelAndAPointIsASingleRunsOptimum) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("examples/vehicle/vehicle_pareto.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  ASSERT_TRUE(study->pareto.enabled());
  const std::vector<slp::CycleRecord> front = RunFront(*study);
  ASSERT_EQ(front.size(), static_cast<size_t>(kPoints));
  std::vector<spec::FrontPoint> points;
  for (const slp::CycleRecord& r : front) {
    std::cout << "point " << r.cycle << ": F " << r.objective_x0 << " m/s^2, |s1| " << r.pareto_value_si / 0.0254
              << " in (level " << r.pareto_level_si / 0.0254 << "), " << r.pareto_state << ", " << r.pareto_cycles
              << " cycles, " << r.pareto_analyses << " analyses\n";
    EXPECT_TRUE(r.accepted) << "point " << r.cycle << ": " << r.rejection_reason;
    points.push_back({r.objective_x0, r.pareto_value_si, r.accepted});
  }
  // Less travel costs comfort: along the front F rises as |s1| falls.
  for (int k = 1; k < kPoints; ++k) {
    EXPECT_GT(front[static_cast<size_t>(k)].objective_x0, front[static_cast<size_t>(k - 1)].objective_x0);
    EXPECT_LT(front[static_cast<size_t>(k)].pareto_value_si, front[static_cast<size_t>(k - 1)].pareto_value_si);
  }
  for (bool dominated : spec::DominatedPoints(points)) EXPECT_FALSE(dominated);

  // The middle point again, as the ride-comfort study with its level as s1's
  // limit (in the study's unit, inches).
  const slp::CycleRecord& middle = front[2];
  spec::Study single = *study;
  single.pareto = spec::Pareto{};
  spec::Constraint& s1 = single.constraints[static_cast<size_t>(study->pareto.constraint)];
  s1.limit = middle.pareto_level_si / s1.si_per_unit;
  absl::StatusOr<LocalRunResult> run = RunStudyLocally(single, LocalRunOptions{});
  ASSERT_TRUE(run.ok()) << run.status();
  EXPECT_EQ(run->outcome.state, slp::RunState::kConverged) << run->end_reason;
  EXPECT_LE(run->outcome.max_violation, 0.0);
  EXPECT_NEAR(run->outcome.objective, middle.objective_x0, kSameOptimumRelative * middle.objective_x0);
  std::cout << "single run at the level " << s1.limit << " in: F " << run->outcome.objective << " (the front's "
            << middle.objective_x0 << "), " << run->outcome.analyses << " analyses\n";
}

// The front with its second objective written as an objective, the largest
// |s1| in inches (`pareto { objective { minimize_max_of: "s1" reduction:
// REDUCTION_MAX_ABS unit: "in" } }`, the constraint s1 taken out of the
// study), is the front against the constraint s1: the same problems but
// for point N's objective (|s1| / its limit against |s1| in inches), whose
// scale may change the runs' path, and so their results within the
// method's tolerance (measured: the same to 10 digits, the min-max's
// iterates not depending on its scale here). Three points each, to keep
// the test short.
TEST(VehicleParetoFront, ASecondObjectiveOfTheSeatTravelGivesTheFrontAgainstItsConstraint) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("examples/vehicle/vehicle_pareto.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  constexpr int kThree = 3;
  spec::Study against = *study;
  against.pareto.points = kThree;
  spec::Study second = against;
  const auto s1 = static_cast<std::size_t>(study->pareto.constraint);
  const spec::Constraint travel = study->constraints[s1];
  second.constraints.erase(second.constraints.begin() + static_cast<std::ptrdiff_t>(s1));
  second.pareto.constraint = -1;
  second.pareto.trades_objective = true;
  second.second_objective = spec::Objective{};
  second.second_objective.form = spec::Objective::Form::kMinimizeMaxOf;
  second.second_objective.output = travel.output;
  second.second_objective.reduction = spec::Reduction::kMaxAbs;
  second.second_objective.unit = "in";
  second.second_objective.si_per_unit = travel.si_per_unit;
  const std::vector<slp::CycleRecord> by_constraint = RunFront(against);
  const std::vector<slp::CycleRecord> by_objective = RunFront(second);
  ASSERT_EQ(by_constraint.size(), static_cast<size_t>(kThree));
  ASSERT_EQ(by_objective.size(), static_cast<size_t>(kThree));
  for (int k = 0; k < kThree; ++k) {
    const slp::CycleRecord& c = by_constraint[static_cast<size_t>(k)];
    const slp::CycleRecord& o = by_objective[static_cast<size_t>(k)];
    // The objective's values are in its unit (inches), the constraint's SI.
    const double travel_in = c.pareto_value_si / travel.si_per_unit;
    std::cout << std::setprecision(10) << "point " << k + 1 << ": F " << c.objective_x0 << " and " << o.objective_x0 << " m/s^2, |s1| "
              << travel_in << " and " << o.pareto_value_si << " in\n";
    EXPECT_TRUE(o.accepted) << "point " << k + 1 << ": " << o.rejection_reason;
    EXPECT_NEAR(o.objective_x0, c.objective_x0, kSameOptimumRelative * c.objective_x0) << "point " << k + 1;
    EXPECT_NEAR(o.pareto_value_si, travel_in, kSameOptimumRelative * travel_in) << "point " << k + 1;
  }
}

// The comfort-against-axle-travel front (vehicle_pareto_travel.study.
// textproto: the second objective the largest of |s2| and |s3| in inches)
// point by point: each interior point's F is that of a separate single run
// of the ride-comfort study whose s2 and s3 limits are lowered to the
// point's level (the largest of the two at or below a level is both at or
// below it).
TEST(VehicleParetoFront, EachInteriorPointOfTheTravelFrontIsASingleRunsOptimum) {
  absl::StatusOr<spec::Study> study =
      spec::io::LoadStudyFile("examples/vehicle/vehicle_pareto_travel.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  ASSERT_TRUE(study->pareto.trades_objective);
  const std::vector<slp::CycleRecord> front = RunFront(*study);
  ASSERT_EQ(front.size(), static_cast<size_t>(kPoints));
  int s2 = -1, s3 = -1;
  for (size_t c = 0; c < study->constraints.size(); ++c) {
    if (study->constraints[c].name == "s2") s2 = static_cast<int>(c);
    if (study->constraints[c].name == "s3") s3 = static_cast<int>(c);
  }
  ASSERT_GE(s2, 0);
  ASSERT_GE(s3, 0);
  for (int k = 1; k + 1 < kPoints; ++k) {
    const slp::CycleRecord& point = front[static_cast<size_t>(k)];
    ASSERT_TRUE(point.accepted) << "point " << k + 1 << ": " << point.rejection_reason;
    // A second objective's level and value are in its unit, inches here.
    const double level_in = point.pareto_level_si;
    spec::Study single = *study;
    single.pareto = spec::Pareto{};
    single.second_objective = spec::Objective{};
    for (int c : {s2, s3}) {
      spec::Constraint& limit = single.constraints[static_cast<size_t>(c)];
      ASSERT_EQ(limit.unit, "in");
      ASSERT_EQ(limit.reduction, spec::Reduction::kMaxAbs);
      limit.limit = std::min(limit.limit, level_in);
    }
    absl::StatusOr<LocalRunResult> run = RunStudyLocally(single, LocalRunOptions{});
    ASSERT_TRUE(run.ok()) << run.status();
    std::cout << std::setprecision(10) << "point " << k + 1 << " (level " << level_in << " in): F "
              << point.objective_x0 << " m/s^2, peak travel " << point.pareto_value_si
              << " in; the single run: F " << run->outcome.objective << ", " << run->outcome.analyses
              << " analyses\n";
    EXPECT_EQ(run->outcome.state, slp::RunState::kConverged) << run->end_reason;
    EXPECT_LE(run->outcome.max_violation, 0.0);
    EXPECT_NEAR(run->outcome.objective, point.objective_x0, kSameOptimumRelative * point.objective_x0)
        << "point " << k + 1;
  }
}

// The front of three objectives (vehicle_pareto3.study.textproto: comfort
// against |s1| and |s2|, a 3 x 3 grid) through the job as the server runs
// it: the anchors end feasible, every feasible grid point meets both its
// levels, no feasible point is beaten in all three objectives by one it
// does not repeat, and the middle grid point is the optimum of a single
// run of the ride-comfort study with both levels written as the ordinary
// limits of s1 and s2.
TEST(VehicleParetoFront, AFrontOfThreeObjectivesMeetsItsLevelsAndItsMiddlePointIsASingleRunsOptimum) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("examples/vehicle/vehicle_pareto3.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  ASSERT_TRUE(study->pareto.three_objectives());
  const std::vector<slp::CycleRecord> front = RunFront(*study);
  ASSERT_EQ(front.size(), static_cast<size_t>(study->pareto.total_points()));
  const spec::Constraint& s1 = study->constraints[static_cast<size_t>(study->pareto.constraint)];
  const spec::Constraint& s2 = study->constraints[static_cast<size_t>(study->pareto.third_constraint)];
  std::vector<spec::FrontPoint> points;
  for (const slp::CycleRecord& r : front) {
    std::cout << std::setprecision(7) << "point " << r.cycle << ": F " << r.objective_x0 << " m/s^2, |s1| "
              << r.pareto_value_si / s1.si_per_unit << " in (level " << r.pareto_level_si / s1.si_per_unit
              << "), |s2| " << r.pareto_value3_si / s2.si_per_unit << " in (level "
              << r.pareto_level3_si / s2.si_per_unit << "), " << r.pareto_state << ", " << r.pareto_analyses
              << " analyses" << (r.accepted ? "" : ": " + r.rejection_reason) << "\n";
    EXPECT_TRUE(r.pareto_three);
    if (r.cycle <= spec::kParetoAnchorsOfThree) {
      EXPECT_TRUE(r.accepted) << "anchor " << r.cycle << ": " << r.rejection_reason;
    }
    if (r.accepted && r.cycle > spec::kParetoAnchorsOfThree) {
      // Met to the method's violation tolerance (docs/method.md section 3).
      EXPECT_LE(r.pareto_value_si, r.pareto_level_si * (1 + 1e-3)) << "point " << r.cycle;
      EXPECT_LE(r.pareto_value3_si, r.pareto_level3_si * (1 + 1e-3)) << "point " << r.cycle;
    }
    points.push_back({r.objective_x0, r.pareto_value_si, r.accepted, r.pareto_value3_si});
  }
  const std::vector<bool> dominated = spec::DominatedPoints(points);
  for (size_t k = 0; k < points.size(); ++k) {
    if (!dominated[k]) continue;
    bool repeats = false;
    for (size_t m = 0; m < points.size(); ++m) {
      repeats |= m != k && points[m].usable &&
                 std::abs(points[m].first - points[k].first) <= kSameOptimumRelative * points[k].first &&
                 std::abs(points[m].second - points[k].second) <= kSameOptimumRelative * points[k].second &&
                 std::abs(points[m].third - points[k].third) <= kSameOptimumRelative * points[k].third;
    }
    EXPECT_TRUE(repeats) << "point " << k + 1 << " is beaten in all three objectives";
  }
  // The middle of the grid: level 1 of each (point 3 + 1 * 3 + 1 + 1 = 8).
  const slp::CycleRecord& middle = front[spec::kParetoAnchorsOfThree + 1 * 3 + 1];
  ASSERT_TRUE(middle.accepted) << middle.rejection_reason;
  spec::Study single = *study;
  single.pareto = spec::Pareto{};
  single.constraints[static_cast<size_t>(study->pareto.constraint)].limit = middle.pareto_level_si / s1.si_per_unit;
  single.constraints[static_cast<size_t>(study->pareto.third_constraint)].limit =
      middle.pareto_level3_si / s2.si_per_unit;
  absl::StatusOr<LocalRunResult> run = RunStudyLocally(single, LocalRunOptions{});
  ASSERT_TRUE(run.ok()) << run.status();
  EXPECT_EQ(run->outcome.state, slp::RunState::kConverged) << run->end_reason;
  EXPECT_LE(run->outcome.max_violation, 0.0);
  EXPECT_NEAR(run->outcome.objective, middle.objective_x0, kSameOptimumRelative * middle.objective_x0);
  std::cout << "single run at the middle point's levels: F " << run->outcome.objective << " (the front's "
            << middle.objective_x0 << "), " << run->outcome.analyses << " analyses\n";
}

// A front's job logged before its points' runs logged their cycles holds
// the points' records alone: its replay emits those again (the runs' cycles
// left out), so it resumes; a log with the cycles replays them.
TEST(VehicleParetoFront, AFrontLoggedWithoutItsRunsCyclesReplaysWithoutThem) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile("examples/vehicle/vehicle_pareto.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  study->pareto.points = 3;
  const auto shared = std::make_shared<const spec::Study>(*study);
  auto make = [&shared] {
    absl::StatusOr<std::unique_ptr<jobs::Job>> job =
        jobs::Job::Create(shared, [] { return lp::MakeClpLpSolver(); });
    EXPECT_TRUE(job.ok()) << job.status();
    return *std::move(job);
  };
  std::unique_ptr<jobs::Job> first = make();
  InProcessEvaluator evaluator(first->study(), first->layout());
  std::vector<jobs::AnalysisRecord> analyses;
  std::vector<std::string> all, points_only;
  jobs::JobRunOptions options;
  options.on_analysis = [&analyses](const jobs::AnalysisRecord& a) { analyses.push_back(a); };
  options.on_record = [&](const slp::CycleRecord& r) {
    all.push_back(jobs::EncodeCycleRecord(r));
    if (r.pareto) points_only.push_back(all.back());
  };
  ASSERT_TRUE(first->Run(evaluator, options).ok());
  ASSERT_EQ(points_only.size(), 3u);
  ASSERT_GT(all.size(), 2 * points_only.size()) << "every run logs its cycles";

  std::unique_ptr<jobs::Job> with_cycles = make();
  absl::StatusOr<std::vector<slp::CycleRecord>> replayed = with_cycles->Replay(analyses, all);
  ASSERT_TRUE(replayed.ok()) << replayed.status();
  EXPECT_TRUE(replayed->empty());
  EXPECT_EQ(with_cycles->state(), jobs::JobState::kCompleted);

  std::unique_ptr<jobs::Job> legacy = make();
  replayed = legacy->Replay(analyses, points_only);
  ASSERT_TRUE(replayed.ok()) << replayed.status();
  EXPECT_TRUE(replayed->empty()) << "nothing beyond the logged points";
  EXPECT_EQ(legacy->state(), jobs::JobState::kCompleted);
}

}  // namespace
}  // namespace mbopt::local_run
