// A Pareto front of three objectives driven directly
// (server/jobs/pareto_grid_run.h) on three spheres in the plane,
//   f_i(x) = 1 + |x - a_i|^2,  a1 = (0, 0), a2 = (2, 0), a3 = (1, 1.6),
// whose Pareto set is the triangle a1 a2 a3 (the 1 keeps each least value
// away from 0, where a relative stopping test says nothing). f1 is the
// objective, f2 and f3 the rows of the two traded constraints. Grid point
// (i, j) minimizes f1 over the intersection of the disks |x - a2|^2 <=
// e2 - 1 and |x - a3|^2 <= e3 - 1, which has a
// closed form (ClosedFormMin): a1 itself if it lies in both disks, else its
// projection on one disk if that lies in the other, else the circles'
// intersection point nearer a1; and no point when the disks are apart.
#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "server/jobs/pareto_grid_run.h"
#include "server/jobs/record_codec.h"
#include "server/lp/make_clp_lp_solver.h"
#include "spec/pareto.h"

namespace mbopt::jobs {
namespace {

constexpr int kLevels = 5;
constexpr int kPoints = spec::kParetoAnchorsOfThree + kLevels * kLevels;
// Each grid point meets its levels to the runs' violation tolerance (1e-8
// here, relative to the level); its f1 is then the closed-form least f1 of
// its levels to 1e-6 (measured: 2.2e-8 at most over the 24 feasible grid
// points; the test prints it).
constexpr double kGridTolerance = 1e-6;
constexpr int kMaxRounds = 40'000;

const Eigen::Vector2d kA1(0, 0), kA2(2, 0), kA3(1, 1.6);

double Sphere(const Eigen::VectorXd& x, const Eigen::Vector2d& a) { return 1 + (x.head<2>() - a).squaredNorm(); }

ParetoGridSetup ThreeSpheres() {
  ParetoGridSetup setup;
  slp::ProblemSpec& p = setup.problem;
  p.variable_names = {"x1", "x2"};
  p.lower = Eigen::Vector2d(-1, -1);
  p.upper = Eigen::Vector2d(3, 3);
  p.initial = Eigen::Vector2d(2.5, 2.5);
  p.objective_form = slp::ObjectiveForm::kScalar;
  p.num_objective_terms = 1;
  p.constraint_names = {"f2", "f3"};
  p.constraint_limits = Eigen::Vector2d(10, 10);
  p.constraint_scales = Eigen::Vector2d(10, 10);
  setup.options.analyses_provide_gradients = true;
  setup.options.max_cycles = 60;
  setup.options.convergence_objective_tolerance = 1e-8;
  setup.options.convergence_violation_tolerance = 1e-8;
  setup.options.convergence_optimality_tolerance = 1e-8;
  setup.row_constraints = {0, 1};
  setup.num_constraints = 2;
  setup.traded_constraints = {0, 1};
  setup.levels = kLevels;
  return setup;
}

AnalysisRecord Answer(const slp::AnalysisRequest& request) {
  AnalysisRecord record;
  record.request_id = request.id;
  const Eigen::VectorXd& x = request.x;
  record.x_scaled.assign(x.data(), x.data() + x.size());
  record.objective_terms = {Sphere(x, kA1)};
  record.constraint_values = {Sphere(x, kA2), Sphere(x, kA3)};
  if (request.want_gradients) {
    record.objective_gradients = {2 * (x[0] - kA1[0]), 2 * (x[1] - kA1[1])};
    record.constraint_gradients = {2 * (x[0] - kA2[0]), 2 * (x[1] - kA2[1]), 2 * (x[0] - kA3[0]), 2 * (x[1] - kA3[1])};
  }
  return record;
}

// The least f1 = 1 + |x - a1|^2 over the disks f2 <= e2, f3 <= e3; none
// when they do not meet. Independent of the optimizer: plane geometry.
std::optional<double> ClosedFormMin(double e2, double e3) {
  if (e2 < 1 || e3 < 1) return std::nullopt;
  const double r2 = std::sqrt(e2 - 1), r3 = std::sqrt(e3 - 1);
  const double d = (kA3 - kA2).norm();
  if (d > r2 + r3) return std::nullopt;
  auto in2 = [&](const Eigen::Vector2d& x) { return (x - kA2).norm() <= r2 * (1 + 1e-12); };
  auto in3 = [&](const Eigen::Vector2d& x) { return (x - kA3).norm() <= r3 * (1 + 1e-12); };
  auto project = [](const Eigen::Vector2d& centre, double radius) -> Eigen::Vector2d {
    const Eigen::Vector2d from = kA1 - centre;
    return from.norm() <= radius ? kA1 : Eigen::Vector2d(centre + radius * from.normalized());
  };
  if (in2(kA1) && in3(kA1)) return 1.0;
  std::optional<double> best;
  for (const Eigen::Vector2d& p : {project(kA2, r2), project(kA3, r3)}) {
    if (in2(p) && in3(p)) best = std::min(best.value_or(std::numeric_limits<double>::infinity()), 1 + (p - kA1).squaredNorm());
  }
  if (best.has_value()) return best;
  // Both circles hold the least point: the intersection nearer a1.
  const double along = (d * d + r2 * r2 - r3 * r3) / (2 * d);
  const double across = std::sqrt(std::max(r2 * r2 - along * along, 0.0));
  const Eigen::Vector2d unit = (kA3 - kA2) / d;
  const Eigen::Vector2d normal(-unit[1], unit[0]);
  const Eigen::Vector2d foot = kA2 + along * unit;
  return 1 + std::min((foot + across * normal - kA1).squaredNorm(), (foot - across * normal - kA1).squaredNorm());
}

std::unique_ptr<ParetoGridRun> Make(ParetoGridSetup setup) {
  absl::StatusOr<std::unique_ptr<ParetoGridRun>> run =
      ParetoGridRun::Create(std::move(setup), [] { return lp::MakeClpLpSolver(); });
  EXPECT_TRUE(run.ok()) << run.status();
  return run.ok() ? *std::move(run) : nullptr;
}

// Drives the front to its end as `workers` workers would, each round
// answering at most `workers` pending requests picked and ordered by
// `seed`. Returns the encoded records in the order they came out.
std::vector<std::string> RunFront(int workers, unsigned seed, std::vector<slp::CycleRecord>* points) {
  std::unique_ptr<ParetoGridRun> run = Make(ThreeSpheres());
  if (run == nullptr) return {};
  std::mt19937 random(seed);
  std::vector<std::string> encoded;
  for (int round = 0; round < kMaxRounds && !run->done(); ++round) {
    std::vector<slp::AnalysisRequest> pending = run->PendingRequests();
    EXPECT_FALSE(pending.empty()) << "the front is not done but asks for nothing";
    if (pending.empty()) break;
    std::shuffle(pending.begin(), pending.end(), random);
    if (static_cast<int>(pending.size()) > workers) pending.resize(static_cast<size_t>(workers));
    for (const slp::AnalysisRequest& request : pending) {
      EXPECT_TRUE(run->Submit(Answer(request)).ok());
      for (slp::CycleRecord& record : run->TakeNewRecords()) {
        encoded.push_back(EncodeCycleRecord(record));
        if (points != nullptr && record.pareto) points->push_back(std::move(record));
      }
    }
  }
  EXPECT_TRUE(run->done());
  return encoded;
}

TEST(ParetoGridRun, ReproducesTheClosedFormMinimaOfTheThreeSpheres) {
  std::vector<slp::CycleRecord> records;
  RunFront(/*workers=*/4, /*seed=*/1, &records);
  ASSERT_EQ(records.size(), static_cast<size_t>(kPoints));
  // The anchors: each sphere's centre, with both bounds left out.
  const std::array<Eigen::Vector2d, 3> centres = {kA1, kA2, kA3};
  for (int a = 0; a < 3; ++a) {
    const slp::CycleRecord& r = records[static_cast<size_t>(a)];
    EXPECT_TRUE(r.accepted) << r.rejection_reason;
    EXPECT_TRUE(r.pareto_three);
    EXPECT_LT((r.x0.head<2>() - centres[static_cast<size_t>(a)]).norm(), 1e-3) << "anchor " << a + 1;
    EXPECT_TRUE(std::isnan(r.pareto_level_si) && std::isnan(r.pareto_level3_si));
  }
  // The box of levels: f2 from the largest of anchors 1 and 3's (5, at
  // a1) down to anchor 2's (1), f3 from 4.56 down to 1, five levels each
  // strictly between.
  const double upper2 = std::max(records[0].pareto_value_si, records[2].pareto_value_si);
  const double upper3 = std::max(records[0].pareto_value3_si, records[1].pareto_value3_si);
  EXPECT_NEAR(upper2, 5.0, 1e-5);
  EXPECT_NEAR(upper3, 4.56, 1e-5);
  int infeasible = 0, met = 0;
  double worst = 0;
  std::vector<spec::FrontPoint> front;
  for (int k = spec::kParetoAnchorsOfThree; k < kPoints; ++k) {
    const slp::CycleRecord& r = records[static_cast<size_t>(k)];
    const int i = (k - spec::kParetoAnchorsOfThree) / kLevels, j = (k - spec::kParetoAnchorsOfThree) % kLevels;
    SCOPED_TRACE(::testing::Message() << "grid point " << k + 1 << " (" << i << ", " << j << "), " << r.pareto_state);
    EXPECT_EQ(r.cycle, k + 1);
    EXPECT_EQ(r.pareto_level_si, spec::ParetoGridLevel(i, kLevels, upper2, records[1].pareto_value_si));
    EXPECT_EQ(r.pareto_level3_si, spec::ParetoGridLevel(j, kLevels, upper3, records[2].pareto_value3_si));
    const std::optional<double> expected = ClosedFormMin(r.pareto_level_si, r.pareto_level3_si);
    if (!expected.has_value()) {
      ++infeasible;
      EXPECT_FALSE(r.accepted);
      EXPECT_NE(r.rejection_reason.find("no feasible design"), std::string::npos) << r.rejection_reason;
      continue;
    }
    ++met;
    EXPECT_TRUE(r.accepted) << r.rejection_reason;
    EXPECT_DOUBLE_EQ(r.objective_x0, Sphere(r.x0, kA1));
    EXPECT_DOUBLE_EQ(r.pareto_value_si, Sphere(r.x0, kA2));
    EXPECT_DOUBLE_EQ(r.pareto_value3_si, Sphere(r.x0, kA3));
    EXPECT_LE(r.pareto_value_si, r.pareto_level_si * (1 + 1e-8));
    EXPECT_LE(r.pareto_value3_si, r.pareto_level3_si * (1 + 1e-8));
    EXPECT_NEAR(r.objective_x0, *expected, kGridTolerance);
    worst = std::max(worst, std::abs(r.objective_x0 - *expected));
  }
  // The disks of the tightest levels (radii 0.816 and 0.770) are 1.887
  // apart: that corner of the grid is empty, the rest is not.
  EXPECT_EQ(infeasible, 1);
  EXPECT_EQ(met, kLevels * kLevels - 1);
  std::cout << "largest |f1 - closed form| over " << met << " grid points: " << worst << "\n";
  // Every feasible point is on the front in 3-D: a point dominated by
  // another is one it repeats (within the runs' tolerance), where a level
  // does not bind.
  for (const slp::CycleRecord& r : records) {
    front.push_back({r.objective_x0, r.pareto_value_si, r.accepted, r.pareto_value3_si});
  }
  const std::vector<bool> dominated = spec::DominatedPoints(front);
  for (size_t k = 0; k < front.size(); ++k) {
    if (!dominated[k]) continue;
    bool repeats = false;
    for (size_t m = 0; m < front.size(); ++m) {
      repeats |= m != k && front[m].usable && std::abs(front[m].first - front[k].first) < 1e-6 &&
                 std::abs(front[m].second - front[k].second) < 1e-6 && std::abs(front[m].third - front[k].third) < 1e-6;
    }
    EXPECT_TRUE(repeats) << "point " << k + 1 << " is dominated by a point it does not repeat";
  }
}

TEST(ParetoGridRun, SameRecordsWhateverTheWorkersAndTheOrderOfResults) {
  std::vector<slp::CycleRecord> points;
  const std::vector<std::string> one = RunFront(1, 7, &points);
  ASSERT_EQ(points.size(), static_cast<size_t>(kPoints));
  EXPECT_EQ(RunFront(3, 11, nullptr), one);
  EXPECT_EQ(RunFront(64, 12345, nullptr), one);
}

TEST(ParetoGridRun, TheAnchorsRunSideBySideAndTheGridWaitsForThem) {
  std::unique_ptr<ParetoGridRun> run = Make(ThreeSpheres());
  ASSERT_NE(run, nullptr);
  const std::vector<slp::AnalysisRequest> pending = run->PendingRequests();
  ASSERT_EQ(pending.size(), 3u);
  for (int a = 0; a < 3; ++a) EXPECT_EQ(pending[static_cast<size_t>(a)].id / ParetoGridRun::kRequestStride, a);
  EXPECT_FALSE(run->IsPending(3 * ParetoGridRun::kRequestStride));
  EXPECT_EQ(run->size(), kPoints);
}

// A resumed job is a new run given the logged results again in the order
// they were logged; it must then go on as the first one would have.
TEST(ParetoGridRun, AFrontResumedFromItsLoggedResultsEndsTheSame) {
  const std::vector<std::string> reference = RunFront(2, 21, nullptr);
  std::unique_ptr<ParetoGridRun> first = Make(ThreeSpheres());
  ASSERT_NE(first, nullptr);
  std::vector<AnalysisRecord> logged;
  std::vector<std::string> encoded;
  std::mt19937 random(21);
  // Killed with part of the grid logged.
  while (!first->done() && first->points_done() < 10) {
    std::vector<slp::AnalysisRequest> pending = first->PendingRequests();
    ASSERT_FALSE(pending.empty());
    std::shuffle(pending.begin(), pending.end(), random);
    const AnalysisRecord answer = Answer(pending.front());
    ASSERT_TRUE(first->Submit(answer).ok());
    logged.push_back(answer);
    for (slp::CycleRecord& r : first->TakeNewRecords()) encoded.push_back(EncodeCycleRecord(r));
  }
  ASSERT_FALSE(first->done());
  std::unique_ptr<ParetoGridRun> resumed = Make(ThreeSpheres());
  ASSERT_NE(resumed, nullptr);
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

TEST(ParetoGridRun, APointsRecordKeepsItsThirdObjectiveThroughTheLog) {
  std::vector<slp::CycleRecord> points;
  RunFront(8, 3, &points);
  ASSERT_EQ(points.size(), static_cast<size_t>(kPoints));
  const slp::CycleRecord& r = points[10];
  absl::StatusOr<slp::CycleRecord> decoded = DecodeCycleRecord(EncodeCycleRecord(r));
  ASSERT_TRUE(decoded.ok()) << decoded.status();
  EXPECT_TRUE(decoded->pareto && decoded->pareto_three);
  EXPECT_EQ(decoded->pareto_level3_si, r.pareto_level3_si);
  EXPECT_EQ(decoded->pareto_value3_si, r.pareto_value3_si);
  EXPECT_EQ(decoded->pareto_value_si, r.pareto_value_si);
}

TEST(ParetoGridRun, AFailedAnchorLeavesTheGridUnrunAndSaysWhy) {
  std::unique_ptr<ParetoGridRun> run = Make(ThreeSpheres());
  ASSERT_NE(run, nullptr);
  std::vector<slp::CycleRecord> records;
  for (int round = 0; round < kMaxRounds && !run->done(); ++round) {
    for (const slp::AnalysisRequest& request : run->PendingRequests()) {
      AnalysisRecord record = Answer(request);
      if (request.id / ParetoGridRun::kRequestStride == 2) {  // anchor 3's analyses fail
        record.objective_terms.clear();
        record.constraint_values.clear();
        record.objective_gradients.clear();
        record.constraint_gradients.clear();
        record.failure = spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, "step size too small");
      }
      ASSERT_TRUE(run->Submit(record).ok());
    }
    for (slp::CycleRecord& r : run->TakeNewRecords()) {
      if (r.pareto) records.push_back(std::move(r));
    }
  }
  ASSERT_EQ(records.size(), static_cast<size_t>(kPoints));
  EXPECT_TRUE(records[0].accepted && records[1].accepted);
  EXPECT_EQ(records[2].pareto_state, "failed");
  for (int k = spec::kParetoAnchorsOfThree; k < kPoints; ++k) {
    EXPECT_EQ(records[static_cast<size_t>(k)].pareto_state, "not_run");
    EXPECT_NE(records[static_cast<size_t>(k)].rejection_reason.find("point 3 (an anchor) has no feasible result"),
              std::string::npos);
  }
}

TEST(ParetoGridRun, RefusesOneConstraintTradedTwiceAndTooFewLevels) {
  ParetoGridSetup twice = ThreeSpheres();
  twice.traded_constraints = {1, 1};
  EXPECT_FALSE(ParetoGridRun::Create(std::move(twice), [] { return lp::MakeClpLpSolver(); }).ok());
  ParetoGridSetup one_level = ThreeSpheres();
  one_level.levels = 1;
  EXPECT_FALSE(ParetoGridRun::Create(std::move(one_level), [] { return lp::MakeClpLpSolver(); }).ok());
}

}  // namespace
}  // namespace mbopt::jobs
