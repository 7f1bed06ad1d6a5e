// A Pareto front driven directly (server/jobs/pareto_run.h) on a
// bi-objective problem whose front is known in closed form, a
// two-variable form of Schaffer's problem SCH (J. D. Schaffer, 1985;
// problem SCH of K. Deb, "Multi-Objective Optimization using Evolutionary
// Algorithms", 2001): two spheres with centres a = (1, 1) and b = (2, 2),
//   f1 = 1 + |x - a|^2,  f2 = 1 + |x - b|^2,  x in [0.5, 3]^2.
// The Pareto-optimal designs are the segment from a to b, and on it
// sqrt(f1 - 1) + sqrt(f2 - 1) = |b - a| = sqrt(2): the front is
//   f1 = 1 + (sqrt(2) - sqrt(f2 - 1))^2,  f2 in [1, 3].
// f1 is the objective; f2 is the one row of the traded constraint (study
// limit 2, so the rows' scale is 2).
#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "server/jobs/pareto_run.h"
#include "server/jobs/record_codec.h"
#include "server/slp/best_design.h"
#include "server/lp/make_clp_lp_solver.h"
#include "spec/pareto.h"

namespace mbopt::jobs {
namespace {

constexpr int kPoints = 9;
// With the runs' tolerances at 1e-5 (TwoSpheres), every point lies on the
// closed-form front to 1e-8 in f1 (measured: 9e-9 at most), since a point
// that meets its level is optimal for that level to the LP's precision;
// 1e-6 leaves room for another LP solver's rounding.
constexpr double kFrontTolerance = 1e-6;
// The anchors are unconstrained minima, found to the runs' stopping test
// (1e-5 in F): measured 1e-6 from f = 1 and 4.5e-6 from f = 3.
constexpr double kAnchorTolerance = 1e-5;
// Each run's requests are far fewer than this; it only stops a broken run.
constexpr int kMaxRounds = 20'000;

double F1(const Eigen::VectorXd& x) { return 1 + (x[0] - 1) * (x[0] - 1) + (x[1] - 1) * (x[1] - 1); }
double F2(const Eigen::VectorXd& x) { return 1 + (x[0] - 2) * (x[0] - 2) + (x[1] - 2) * (x[1] - 2); }

double FrontF1(double f2) {
  const double d = std::sqrt(2.0) - std::sqrt(std::max(f2 - 1.0, 0.0));
  return 1 + d * d;
}

ParetoSetup TwoSpheres(bool gradients) {
  ParetoSetup setup;
  slp::ProblemSpec& p = setup.problem;
  p.variable_names = {"x1", "x2"};
  p.lower = Eigen::Vector2d(0.5, 0.5);
  p.upper = Eigen::Vector2d(3, 3);
  p.initial = Eigen::Vector2d(2.5, 0.8);
  p.objective_form = slp::ObjectiveForm::kScalar;
  p.num_objective_terms = 1;
  p.constraint_names = {"f2"};
  p.constraint_limits = Eigen::VectorXd::Constant(1, 2.0);
  p.constraint_scales = Eigen::VectorXd::Constant(1, 2.0);
  setup.options.analyses_provide_gradients = gradients;
  setup.options.max_cycles = 60;
  // Tighter than the method's defaults (0.005), so that the front is
  // checked to a tolerance that says something of the method rather than
  // of its stopping test.
  setup.options.convergence_objective_tolerance = 1e-5;
  setup.options.convergence_violation_tolerance = 1e-5;
  setup.options.convergence_optimality_tolerance = 1e-5;
  setup.row_constraints = {0};
  setup.num_constraints = 1;
  setup.traded_constraint = 0;
  setup.points = kPoints;
  return setup;
}

AnalysisRecord Answer(const slp::AnalysisRequest& request) {
  AnalysisRecord record;
  record.request_id = request.id;
  record.x_scaled.assign(request.x.data(), request.x.data() + request.x.size());
  record.objective_terms = {F1(request.x)};
  record.constraint_values = {F2(request.x)};
  if (request.want_gradients) {
    record.objective_gradients = {2 * (request.x[0] - 1), 2 * (request.x[1] - 1)};
    record.constraint_gradients = {2 * (request.x[0] - 2), 2 * (request.x[1] - 2)};
  }
  return record;
}

// The points' records among encoded records (the others are their runs'
// cycles).
size_t PointsIn(const std::vector<std::string>& encoded) {
  size_t points = 0;
  for (const std::string& bytes : encoded) {
    absl::StatusOr<slp::CycleRecord> record = DecodeCycleRecord(bytes);
    EXPECT_TRUE(record.ok()) << record.status();
    if (record.ok() && record->pareto) ++points;
  }
  return points;
}

// Drives the front to its end as `workers` workers would: each round answers
// at most `workers` of the pending requests, picked and ordered by `seed`.
// Returns the encoded records in the order they came out.
std::vector<std::string> RunFront(ParetoSetup setup, int workers, unsigned seed, std::vector<slp::CycleRecord>* out) {
  absl::StatusOr<std::unique_ptr<ParetoRun>> run =
      ParetoRun::Create(std::move(setup), [] { return lp::MakeClpLpSolver(); });
  EXPECT_TRUE(run.ok()) << run.status();
  if (!run.ok()) return {};
  std::mt19937 random(seed);
  std::vector<std::string> encoded;
  for (int round = 0; round < kMaxRounds && !(*run)->done(); ++round) {
    std::vector<slp::AnalysisRequest> pending = (*run)->PendingRequests();
    EXPECT_FALSE(pending.empty()) << "the front is not done but asks for nothing";
    if (pending.empty()) break;
    std::shuffle(pending.begin(), pending.end(), random);
    if (static_cast<int>(pending.size()) > workers) pending.resize(static_cast<size_t>(workers));
    for (const slp::AnalysisRequest& request : pending) {
      EXPECT_TRUE((*run)->Submit(Answer(request)).ok());
      for (slp::CycleRecord& record : (*run)->TakeNewRecords()) {
        encoded.push_back(EncodeCycleRecord(record));
        if (out != nullptr && record.pareto) out->push_back(std::move(record));
      }
    }
  }
  EXPECT_TRUE((*run)->done());
  return encoded;
}

std::vector<std::string> RunFront(bool gradients, int workers, unsigned seed, std::vector<slp::CycleRecord>* out) {
  return RunFront(TwoSpheres(gradients), workers, seed, out);
}

ParetoSetup RefinedTwoSpheres(int refine) {
  ParetoSetup setup = TwoSpheres(/*gradients=*/true);
  setup.refine = refine;
  return setup;
}

TEST(ParetoRun, ReproducesTheClosedFormFrontOfTheTwoSpheres) {
  std::vector<slp::CycleRecord> records;
  RunFront(/*gradients=*/true, /*workers=*/4, /*seed=*/1, &records);
  ASSERT_EQ(records.size(), static_cast<size_t>(kPoints));
  for (int k = 0; k < kPoints; ++k) {
    const slp::CycleRecord& r = records[static_cast<size_t>(k)];
    SCOPED_TRACE(::testing::Message() << "point " << k + 1 << " (" << r.pareto_state << ")");
    EXPECT_TRUE(r.pareto);
    EXPECT_EQ(r.cycle, k + 1);
    EXPECT_TRUE(r.accepted) << r.rejection_reason;
    const double f1 = F1(r.x0);
    const double f2 = F2(r.x0);
    EXPECT_DOUBLE_EQ(r.objective_x0, f1);
    EXPECT_DOUBLE_EQ(r.pareto_value_si, f2);
    EXPECT_NEAR(f1, FrontF1(f2), kFrontTolerance) << "f2 = " << f2;
  }
  // The anchors: the objective's own optimum (f1 = 1 at a, f2 = 3 there)
  // and the traded value's (f2 = 1 at b, f1 = 3).
  EXPECT_NEAR(records.front().objective_x0, 1.0, kAnchorTolerance);
  EXPECT_NEAR(records.front().pareto_value_si, 3.0, kAnchorTolerance);
  EXPECT_NEAR(records.back().pareto_value_si, 1.0, kAnchorTolerance);
  EXPECT_NEAR(records.back().objective_x0, 3.0, kAnchorTolerance);
  EXPECT_TRUE(std::isnan(records.front().pareto_level_si));
  // The levels between are evenly spread between the anchors' values, and
  // each point meets its level.
  for (int k = 1; k + 1 < kPoints; ++k) {
    const slp::CycleRecord& r = records[static_cast<size_t>(k)];
    const double level = spec::ParetoLevel(k, kPoints, records.front().pareto_value_si,
                                           records.back().pareto_value_si);
    EXPECT_EQ(r.pareto_level_si, level);
    // Met within the runs' violation tolerance (1e-5 of the level).
    EXPECT_LE(r.pareto_value_si, level * (1 + 1e-5));
  }
  std::vector<spec::FrontPoint> front;
  for (const slp::CycleRecord& r : records) front.push_back({r.objective_x0, r.pareto_value_si, r.accepted});
  for (bool dominated : spec::DominatedPoints(front)) EXPECT_FALSE(dominated);
}

TEST(ParetoRun, SameRecordsWhateverTheWorkersAndTheOrderOfResults) {
  const std::vector<std::string> one = RunFront(/*gradients=*/false, 1, 7, nullptr);
  ASSERT_EQ(PointsIn(one), static_cast<size_t>(kPoints));
  EXPECT_EQ(RunFront(false, 3, 11, nullptr), one);
  EXPECT_EQ(RunFront(false, 64, 12345, nullptr), one);
}

TEST(ParetoRun, PointsOfOneGenerationRunSideBySide) {
  absl::StatusOr<std::unique_ptr<ParetoRun>> run =
      ParetoRun::Create(TwoSpheres(true), [] { return lp::MakeClpLpSolver(); });
  ASSERT_TRUE(run.ok()) << run.status();
  // At the start both anchors ask for their first design.
  std::vector<slp::AnalysisRequest> pending = (*run)->PendingRequests();
  ASSERT_EQ(pending.size(), 2u);
  EXPECT_EQ(pending[0].id / ParetoRun::kRequestStride, 0);
  EXPECT_EQ(pending[1].id / ParetoRun::kRequestStride, kPoints - 1);
  EXPECT_FALSE((*run)->IsPending(1 * ParetoRun::kRequestStride));
  slp::AnalysisRequest not_started = pending[0];
  not_started.id = 5 * ParetoRun::kRequestStride;
  EXPECT_FALSE((*run)->Submit(Answer(not_started)).ok());
}

TEST(ParetoRun, ObjectivesThatDoNotConflictLeaveThePointsBetweenUnrun) {
  ParetoSetup setup = TwoSpheres(true);
  // The traded row is f1 itself: where f1 is least, so is the row.
  auto answer_same = [](const slp::AnalysisRequest& request) {
    AnalysisRecord record = Answer(request);
    record.constraint_values = {F1(request.x)};
    if (request.want_gradients) record.constraint_gradients = record.objective_gradients;
    return record;
  };
  absl::StatusOr<std::unique_ptr<ParetoRun>> run =
      ParetoRun::Create(std::move(setup), [] { return lp::MakeClpLpSolver(); });
  ASSERT_TRUE(run.ok()) << run.status();
  std::vector<slp::CycleRecord> records;
  for (int round = 0; round < kMaxRounds && !(*run)->done(); ++round) {
    for (const slp::AnalysisRequest& request : (*run)->PendingRequests()) {
      ASSERT_TRUE((*run)->Submit(answer_same(request)).ok());
    }
    for (slp::CycleRecord& r : (*run)->TakeNewRecords()) {
      if (r.pareto) records.push_back(std::move(r));
    }
  }
  ASSERT_EQ(records.size(), static_cast<size_t>(kPoints));
  for (int k = 1; k + 1 < kPoints; ++k) {
    EXPECT_EQ(records[static_cast<size_t>(k)].pareto_state, "not_run");
    EXPECT_NE(records[static_cast<size_t>(k)].rejection_reason.find("do not conflict"), std::string::npos);
    EXPECT_FALSE(records[static_cast<size_t>(k)].accepted);
  }
}

TEST(ParetoRun, AFailedEndLeavesThePointsBetweenUnrunAndSaysWhy) {
  absl::StatusOr<std::unique_ptr<ParetoRun>> run =
      ParetoRun::Create(TwoSpheres(true), [] { return lp::MakeClpLpSolver(); });
  ASSERT_TRUE(run.ok()) << run.status();
  std::vector<slp::CycleRecord> records;
  for (int round = 0; round < kMaxRounds && !(*run)->done(); ++round) {
    for (const slp::AnalysisRequest& request : (*run)->PendingRequests()) {
      AnalysisRecord record = Answer(request);
      // Every analysis of the last point's run fails.
      if (request.id / ParetoRun::kRequestStride == kPoints - 1) {
        record.objective_terms.clear();
        record.constraint_values.clear();
        record.objective_gradients.clear();
        record.constraint_gradients.clear();
        record.failure = spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, "step size too small");
      }
      ASSERT_TRUE((*run)->Submit(record).ok());
    }
    for (slp::CycleRecord& r : (*run)->TakeNewRecords()) {
      if (r.pareto) records.push_back(std::move(r));
    }
  }
  ASSERT_EQ(records.size(), static_cast<size_t>(kPoints));
  EXPECT_TRUE(records.front().accepted);
  EXPECT_EQ(records.back().pareto_state, "failed");
  EXPECT_FALSE(records.back().accepted);
  EXPECT_TRUE(std::isnan(records.back().pareto_value_si));
  for (int k = 1; k + 1 < kPoints; ++k) {
    EXPECT_EQ(records[static_cast<size_t>(k)].pareto_state, "not_run");
    EXPECT_NE(records[static_cast<size_t>(k)].rejection_reason.find("point 9 (an anchor) has no feasible result"),
              std::string::npos)
        << records[static_cast<size_t>(k)].rejection_reason;
  }
}

// With the levels evenly spread in f2, the sampled SCH front bends most
// towards its f2 = 1 end, where f1 climbs from 1.84 to 3 over the last
// segment: the turns at points 6, 7 and 8 are 0.20, 0.26 and 0.43 rad
// against 0.15 or less before, so the three added points halve the last
// three segments (f2 from 1.75 down to 1).
TEST(ParetoRun, RefinedPointsHalveTheSegmentsWhereTheFrontBends) {
  constexpr int kRefine = 3;
  std::vector<slp::CycleRecord> records;
  RunFront(RefinedTwoSpheres(kRefine), /*workers=*/4, /*seed=*/5, &records);
  ASSERT_EQ(records.size(), static_cast<size_t>(kPoints + kRefine));
  std::vector<spec::FrontPoint> first;
  for (int k = 0; k < kPoints; ++k) {
    const slp::CycleRecord& r = records[static_cast<size_t>(k)];
    first.push_back({r.objective_x0, r.pareto_value_si, r.accepted});
  }
  const std::vector<spec::RefinementSegment> segments = spec::RefinementSegments(first, kRefine);
  ASSERT_EQ(segments.size(), static_cast<size_t>(kRefine));
  for (int j = 0; j < kRefine; ++j) {
    const slp::CycleRecord& r = records[static_cast<size_t>(kPoints + j)];
    SCOPED_TRACE(::testing::Message() << "added point " << kPoints + j + 1 << " (" << r.pareto_state << ")");
    EXPECT_EQ(r.cycle, kPoints + j + 1);
    EXPECT_TRUE(r.accepted) << r.rejection_reason;
    // The last three segments of the first nine points, in the front's order.
    EXPECT_EQ(segments[static_cast<size_t>(j)].from, kPoints - kRefine - 1 + j);
    EXPECT_EQ(segments[static_cast<size_t>(j)].to, kPoints - kRefine + j);
    const double upper = records[static_cast<size_t>(segments[static_cast<size_t>(j)].from)].pareto_value_si;
    const double lower = records[static_cast<size_t>(segments[static_cast<size_t>(j)].to)].pareto_value_si;
    EXPECT_EQ(r.pareto_level_si, 0.5 * (upper + lower));
    EXPECT_LT(r.pareto_level_si, 1.75 + kAnchorTolerance);
    EXPECT_LE(r.pareto_value_si, r.pareto_level_si * (1 + 1e-5));
    EXPECT_GT(r.pareto_value_si, lower);
    const double f1 = F1(r.x0);
    EXPECT_DOUBLE_EQ(r.objective_x0, f1);
    EXPECT_NEAR(f1, FrontF1(F2(r.x0)), kFrontTolerance);
  }
  // The analyses count on through the added points.
  EXPECT_GT(records.back().analyses_total, records[kPoints - 1].analyses_total);
}

TEST(ParetoRun, RefinedFrontIsTheSameWhateverTheWorkersAndTheOrderOfResults) {
  const std::vector<std::string> one = RunFront(RefinedTwoSpheres(4), 1, 7, nullptr);
  ASSERT_EQ(PointsIn(one), static_cast<size_t>(kPoints + 4));
  EXPECT_EQ(RunFront(RefinedTwoSpheres(4), 3, 11, nullptr), one);
  EXPECT_EQ(RunFront(RefinedTwoSpheres(4), 64, 12345, nullptr), one);
}

// A resumed job is a new ParetoRun given the logged results again in the
// order they were logged; it must then go on as the first one would have.
TEST(ParetoRun, ARefinedFrontResumedFromItsLoggedResultsEndsTheSame) {
  const std::vector<std::string> reference = RunFront(RefinedTwoSpheres(2), 2, 21, nullptr);
  ASSERT_EQ(PointsIn(reference), static_cast<size_t>(kPoints + 2));
  auto make = [] {
    absl::StatusOr<std::unique_ptr<ParetoRun>> run =
        ParetoRun::Create(RefinedTwoSpheres(2), [] { return lp::MakeClpLpSolver(); });
    EXPECT_TRUE(run.ok()) << run.status();
    return *std::move(run);
  };
  // Killed once the first nine points and part of the added ones are in.
  std::unique_ptr<ParetoRun> first = make();
  std::vector<AnalysisRecord> logged;
  std::vector<std::string> encoded;
  std::mt19937 random(21);
  bool refinement_started = false;
  for (int round = 0; round < kMaxRounds && !first->done(); ++round) {
    std::vector<slp::AnalysisRequest> pending = first->PendingRequests();
    std::shuffle(pending.begin(), pending.end(), random);
    for (const slp::AnalysisRequest& r : pending) refinement_started |= r.id / ParetoRun::kRequestStride >= kPoints;
    if (refinement_started && logged.size() % 3 == 0) break;
    const AnalysisRecord answer = Answer(pending.front());
    ASSERT_TRUE(first->Submit(answer).ok());
    logged.push_back(answer);
    for (slp::CycleRecord& r : first->TakeNewRecords()) encoded.push_back(EncodeCycleRecord(r));
  }
  ASSERT_TRUE(refinement_started);
  ASSERT_FALSE(first->done());
  std::unique_ptr<ParetoRun> resumed = make();
  std::vector<std::string> replayed;
  for (const AnalysisRecord& record : logged) {
    ASSERT_TRUE(resumed->Submit(record).ok());
    for (slp::CycleRecord& r : resumed->TakeNewRecords()) replayed.push_back(EncodeCycleRecord(r));
  }
  EXPECT_EQ(replayed, encoded);
  for (int round = 0; round < kMaxRounds && !resumed->done(); ++round) {
    for (const slp::AnalysisRequest& request : resumed->PendingRequests()) {
      ASSERT_TRUE(resumed->Submit(Answer(request)).ok());
      for (slp::CycleRecord& r : resumed->TakeNewRecords()) replayed.push_back(EncodeCycleRecord(r));
    }
  }
  EXPECT_EQ(replayed, reference);
}

TEST(ParetoRun, AddedPointsWithoutASegmentEndUnrunAndSayWhy) {
  ParetoSetup setup = RefinedTwoSpheres(2);
  absl::StatusOr<std::unique_ptr<ParetoRun>> run =
      ParetoRun::Create(std::move(setup), [] { return lp::MakeClpLpSolver(); });
  ASSERT_TRUE(run.ok()) << run.status();
  std::vector<slp::CycleRecord> records;
  for (int round = 0; round < kMaxRounds && !(*run)->done(); ++round) {
    for (const slp::AnalysisRequest& request : (*run)->PendingRequests()) {
      AnalysisRecord record = Answer(request);
      // The last anchor fails: the points between are not run, and the
      // front of the first nine points is the first anchor alone.
      if (request.id / ParetoRun::kRequestStride == kPoints - 1) {
        record.objective_terms.clear();
        record.constraint_values.clear();
        record.objective_gradients.clear();
        record.constraint_gradients.clear();
        record.failure = spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, "step size too small");
      }
      ASSERT_TRUE((*run)->Submit(record).ok());
    }
    for (slp::CycleRecord& r : (*run)->TakeNewRecords()) {
      if (r.pareto) records.push_back(std::move(r));
    }
  }
  ASSERT_EQ(records.size(), static_cast<size_t>(kPoints + 2));
  for (int k = kPoints; k < kPoints + 2; ++k) {
    EXPECT_EQ(records[static_cast<size_t>(k)].pareto_state, "not_run");
    EXPECT_EQ(records[static_cast<size_t>(k)].rejection_reason,
              "the front of the first 9 points has only 0 segments to refine");
  }
}

ParetoSetup TwiceRefinedTwoSpheres(int refine, int refine_again) {
  ParetoSetup setup = RefinedTwoSpheres(refine);
  setup.refine_again = refine_again;
  return setup;
}

// A second generation (refine_again): once the nine points and the three
// added ones have ended, three more halve the segments the front of all
// twelve scores highest, their levels halfway between those segments'
// ends, and they too lie on the closed-form front.
TEST(ParetoRun, ARefinedFrontRefinedAgainHalvesTheSegmentsOfTheWholeRefinedFront) {
  constexpr int kRefine = 3;
  constexpr int kAgain = 3;
  std::vector<slp::CycleRecord> records;
  RunFront(TwiceRefinedTwoSpheres(kRefine, kAgain), /*workers=*/4, /*seed=*/9, &records);
  ASSERT_EQ(records.size(), static_cast<size_t>(kPoints + kRefine + kAgain));
  std::vector<spec::FrontPoint> refined;
  for (int k = 0; k < kPoints + kRefine; ++k) {
    const slp::CycleRecord& r = records[static_cast<size_t>(k)];
    refined.push_back({r.objective_x0, r.pareto_value_si, r.accepted});
  }
  const std::vector<spec::RefinementSegment> segments = spec::RefinementSegments(refined, kAgain);
  ASSERT_EQ(segments.size(), static_cast<size_t>(kAgain));
  bool halves_an_added_points_segment = false;
  for (int j = 0; j < kAgain; ++j) {
    const slp::CycleRecord& r = records[static_cast<size_t>(kPoints + kRefine + j)];
    SCOPED_TRACE(::testing::Message() << "point " << kPoints + kRefine + j + 1 << " (" << r.pareto_state << ")");
    EXPECT_TRUE(r.accepted) << r.rejection_reason;
    const spec::RefinementSegment& segment = segments[static_cast<size_t>(j)];
    halves_an_added_points_segment |= segment.from >= kPoints || segment.to >= kPoints;
    const double upper = records[static_cast<size_t>(segment.from)].pareto_value_si;
    const double lower = records[static_cast<size_t>(segment.to)].pareto_value_si;
    EXPECT_EQ(r.pareto_level_si, 0.5 * (upper + lower));
    EXPECT_LE(r.pareto_value_si, r.pareto_level_si * (1 + 1e-5));
    EXPECT_GT(r.pareto_value_si, lower);
    EXPECT_NEAR(F1(r.x0), FrontF1(F2(r.x0)), kFrontTolerance);
  }
  // The second generation refines the first's work, not only the nine
  // points' segments: one of its segments ends at an added point.
  EXPECT_TRUE(halves_an_added_points_segment);
  for (bool dominated : spec::DominatedPoints(refined)) EXPECT_FALSE(dominated);
}

TEST(ParetoRun, ATwiceRefinedFrontIsTheSameWhateverTheWorkersAndAfterAReplay) {
  const std::vector<std::string> one = RunFront(TwiceRefinedTwoSpheres(2, 3), 1, 7, nullptr);
  ASSERT_EQ(PointsIn(one), static_cast<size_t>(kPoints + 2 + 3));
  EXPECT_EQ(RunFront(TwiceRefinedTwoSpheres(2, 3), 3, 11, nullptr), one);
  EXPECT_EQ(RunFront(TwiceRefinedTwoSpheres(2, 3), 64, 12345, nullptr), one);
  // Replayed from the first run's results in the order they came, cut off
  // once the second generation has started, then continued.
  auto make = [] {
    absl::StatusOr<std::unique_ptr<ParetoRun>> run =
        ParetoRun::Create(TwiceRefinedTwoSpheres(2, 3), [] { return lp::MakeClpLpSolver(); });
    EXPECT_TRUE(run.ok()) << run.status();
    return *std::move(run);
  };
  std::unique_ptr<ParetoRun> first = make();
  std::vector<AnalysisRecord> logged;
  std::mt19937 random(3);
  bool second_generation = false;
  for (int round = 0; round < kMaxRounds && !first->done() && !second_generation; ++round) {
    std::vector<slp::AnalysisRequest> pending = first->PendingRequests();
    std::shuffle(pending.begin(), pending.end(), random);
    const AnalysisRecord answer = Answer(pending.front());
    ASSERT_TRUE(first->Submit(answer).ok());
    logged.push_back(answer);
    first->TakeNewRecords();
    for (const slp::AnalysisRequest& r : first->PendingRequests()) {
      second_generation |= r.id / ParetoRun::kRequestStride >= kPoints + 2;
    }
  }
  ASSERT_TRUE(second_generation);
  std::unique_ptr<ParetoRun> resumed = make();
  std::vector<std::string> replayed;
  for (const AnalysisRecord& record : logged) {
    ASSERT_TRUE(resumed->Submit(record).ok());
    for (slp::CycleRecord& r : resumed->TakeNewRecords()) replayed.push_back(EncodeCycleRecord(r));
  }
  for (int round = 0; round < kMaxRounds && !resumed->done(); ++round) {
    for (const slp::AnalysisRequest& request : resumed->PendingRequests()) {
      ASSERT_TRUE(resumed->Submit(Answer(request)).ok());
      for (slp::CycleRecord& r : resumed->TakeNewRecords()) replayed.push_back(EncodeCycleRecord(r));
    }
  }
  EXPECT_EQ(replayed, one);
}

TEST(ParetoRun, RefusesASecondGenerationWithoutAFirstOrWithMorePointsThanSegments) {
  absl::StatusOr<std::unique_ptr<ParetoRun>> without =
      ParetoRun::Create(TwiceRefinedTwoSpheres(0, 2), [] { return lp::MakeClpLpSolver(); });
  EXPECT_FALSE(without.ok());
  absl::StatusOr<std::unique_ptr<ParetoRun>> too_many =
      ParetoRun::Create(TwiceRefinedTwoSpheres(2, kPoints + 2), [] { return lp::MakeClpLpSolver(); });
  ASSERT_FALSE(too_many.ok());
  EXPECT_EQ(too_many.status().message(),
            "a refined front of 11 points can be refined again by 0 to 10 points (with refine above 0), got 11");
}

TEST(ParetoRun, RefusesMoreAddedPointsThanSegments) {
  absl::StatusOr<std::unique_ptr<ParetoRun>> run =
      ParetoRun::Create(RefinedTwoSpheres(kPoints), [] { return lp::MakeClpLpSolver(); });
  ASSERT_FALSE(run.ok());
  EXPECT_EQ(run.status().message(), "a front of 9 points can be refined by 0 to 8 points, got 9");
}

// Each point's run logs its own cycle records, all of them just before the
// point's record: the run's history, whose best design is the point's
// result. Points not run have none.
TEST(ParetoRun, EachPointsRunLogsItsCyclesJustBeforeThePoint) {
  ParetoSetup setup = TwoSpheres(/*gradients=*/true);
  absl::StatusOr<std::unique_ptr<ParetoRun>> run =
      ParetoRun::Create(std::move(setup), [] { return lp::MakeClpLpSolver(); });
  ASSERT_TRUE(run.ok()) << run.status();
  std::mt19937 random(5);
  std::vector<slp::CycleRecord> records;
  for (int round = 0; round < kMaxRounds && !(*run)->done(); ++round) {
    std::vector<slp::AnalysisRequest> pending = (*run)->PendingRequests();
    std::shuffle(pending.begin(), pending.end(), random);
    for (const slp::AnalysisRequest& request : pending) {
      ASSERT_TRUE((*run)->Submit(Answer(request)).ok());
      for (slp::CycleRecord& r : (*run)->TakeNewRecords()) records.push_back(std::move(r));
    }
  }
  ASSERT_TRUE((*run)->done());
  std::vector<slp::CycleRecord> history;
  int points = 0;
  for (const slp::CycleRecord& r : records) {
    if (r.pareto_point > 0) {
      EXPECT_FALSE(r.pareto);
      EXPECT_FALSE(r.design_set);
      EXPECT_EQ(r.pareto_point, points + 1) << "a run's cycle after its point's record";
      history.push_back(r);
      continue;
    }
    ASSERT_TRUE(r.pareto);
    ++points;
    SCOPED_TRACE(::testing::Message() << "point " << r.cycle);
    EXPECT_EQ(r.cycle, points);
    ASSERT_FALSE(history.empty());
    // The run's cycles, in order, as the core emitted them.
    EXPECT_EQ(history.front().cycle, 1);
    EXPECT_EQ(history.back().cycle, r.pareto_cycles);
    for (std::size_t j = 1; j < history.size(); ++j) {
      EXPECT_GE(history[j].cycle, history[j - 1].cycle);
      EXPECT_GE(history[j].analyses_total, history[j - 1].analyses_total);
    }
    EXPECT_LE(history.back().analyses_total, r.pareto_analyses);
    slp::BestDesign best;
    for (const slp::CycleRecord& c : history) best.OfferRecord(c);
    ASSERT_TRUE(best.best().has_value());
    EXPECT_EQ(best.best()->x, r.x0) << "the point's result is its run's best design";
    history.clear();
  }
  EXPECT_EQ(points, kPoints);
  EXPECT_TRUE(history.empty());
}

// A run's cycle record keeps its point's number and every field through the
// log's encoding; a point's record stays as it was (version 5).
TEST(ParetoRunRecords, RunCyclesKeepTheirPointThroughAnEncodeAndDecode) {
  const std::vector<std::string> encoded = RunFront(true, 2, 3, nullptr);
  int run_cycles = 0;
  for (const std::string& bytes : encoded) {
    absl::StatusOr<slp::CycleRecord> decoded = DecodeCycleRecord(bytes);
    ASSERT_TRUE(decoded.ok()) << decoded.status();
    EXPECT_EQ(EncodeCycleRecord(*decoded), bytes);
    EXPECT_EQ(bytes[0], decoded->pareto_point > 0 ? 6 : 5);
    if (decoded->pareto_point > 0) {
      ++run_cycles;
      EXPECT_LE(decoded->pareto_point, kPoints);
      EXPECT_FALSE(decoded->design_set);
      EXPECT_FALSE(decoded->pareto);
      EXPECT_EQ(decoded->x0.size(), 2);
    }
  }
  EXPECT_GE(run_cycles, kPoints);
}

// A job logged before the runs' cycles were resumes with its log: a front
// that does not log them emits its points' records alone, the same bytes.
TEST(ParetoRun, WithoutItsRunsCyclesEmitsThePointsAlone) {
  std::vector<std::string> points;
  for (const std::string& bytes : RunFront(true, 3, 9, nullptr)) {
    if (DecodeCycleRecord(bytes)->pareto) points.push_back(bytes);
  }
  absl::StatusOr<std::unique_ptr<ParetoRun>> run =
      ParetoRun::Create(TwoSpheres(true), [] { return lp::MakeClpLpSolver(); });
  ASSERT_TRUE(run.ok()) << run.status();
  (*run)->LogRunCycles(false);
  std::vector<std::string> emitted;
  for (int round = 0; round < kMaxRounds && !(*run)->done(); ++round) {
    for (const slp::AnalysisRequest& request : (*run)->PendingRequests()) {
      ASSERT_TRUE((*run)->Submit(Answer(request)).ok());
      for (slp::CycleRecord& r : (*run)->TakeNewRecords()) emitted.push_back(EncodeCycleRecord(r));
    }
  }
  EXPECT_EQ(emitted, points);
}

TEST(ParetoRunRecords, ArePointRecordsAfterAnEncodeAndDecode) {
  std::vector<slp::CycleRecord> records;
  RunFront(true, 2, 3, &records);
  ASSERT_FALSE(records.empty());
  for (const slp::CycleRecord& r : records) {
    absl::StatusOr<slp::CycleRecord> decoded = DecodeCycleRecord(EncodeCycleRecord(r));
    ASSERT_TRUE(decoded.ok()) << decoded.status();
    EXPECT_TRUE(decoded->pareto);
    EXPECT_TRUE(decoded->design_set);
    EXPECT_EQ(EncodeCycleRecord(*decoded), EncodeCycleRecord(r));
    EXPECT_EQ(decoded->pareto_state, r.pareto_state);
    EXPECT_EQ(decoded->pareto_analyses, r.pareto_analyses);
  }
}

}  // namespace
}  // namespace mbopt::jobs
