// A Pareto front whose second objective is an objective of its own
// (spec::StudyLayout::second_objective_factors), driven directly on the
// two spheres of Schaffer's problem SCH (pareto_run_test.cc):
//   f1 = 1 + |x - a|^2,  f2 = 1 + |x - b|^2,  a = (1, 1), b = (2, 2),
// whose front is sqrt(f1 - 1) + sqrt(f2 - 1) = sqrt(2). f2 is not one
// constraint row here but what the study's layout makes of an objective:
//  - a weighted sum of two one-value terms, u = ((x1 - 2)^2 + 0.5) / 2
//    with weight 2 and v = 4 ((x2 - 2)^2 + 0.5) with weight 1/4, so
//    f2 = 2 u + v / 4 only through the weights;
//  - the largest of two weighted rows, p = f2 / 2 with weight 2 and
//    q = (f2 - 1/2) / 4 with weight 4, so f2 = max(2 p, 4 q) = 2 p, each
//    row bounded at level / weight.
// The study also has an ordinary constraint row, x1 + x2 <= 10 (never
// active), which every point keeps.
#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "server/jobs/pareto_run.h"
#include "server/jobs/record_codec.h"
#include "server/lp/make_clp_lp_solver.h"
#include "spec/layout.h"
#include "spec/pareto.h"

namespace mbopt::jobs {
namespace {

constexpr int kPoints = 7;
// As in pareto_run_test.cc: with the runs' tolerances at 1e-5 every point
// lies on the closed-form front far closer than this.
constexpr double kFrontTolerance = 1e-6;
constexpr double kAnchorTolerance = 1e-5;
constexpr int kMaxRounds = 20'000;

enum class Form { kSum, kLargest };

double F1(const Eigen::VectorXd& x) { return 1 + (x[0] - 1) * (x[0] - 1) + (x[1] - 1) * (x[1] - 1); }
double F2(const Eigen::VectorXd& x) { return 1 + (x[0] - 2) * (x[0] - 2) + (x[1] - 2) * (x[1] - 2); }

double FrontF1(double f2) {
  const double d = std::sqrt(2.0) - std::sqrt(std::max(f2 - 1.0, 0.0));
  return 1 + d * d;
}

ParetoSetup TwoSpheres(Form form) {
  ParetoSetup setup;
  slp::ProblemSpec& p = setup.problem;
  p.variable_names = {"x1", "x2"};
  p.lower = Eigen::Vector2d(0.5, 0.5);
  p.upper = Eigen::Vector2d(3, 3);
  p.initial = Eigen::Vector2d(2.5, 0.8);
  p.objective_form = slp::ObjectiveForm::kScalar;
  p.num_objective_terms = 1;
  // The constraint's row, then the second objective's two rows as the
  // layout gives them: limit 0, scale 1.
  p.constraint_names = {"sum upper", "second objective[0]", "second objective[1]"};
  p.constraint_limits = Eigen::Vector3d(10, 0, 0);
  p.constraint_scales = Eigen::Vector3d(10, 1, 1);
  setup.options.analyses_provide_gradients = true;
  setup.options.max_cycles = 60;
  setup.options.convergence_objective_tolerance = 1e-5;
  setup.options.convergence_violation_tolerance = 1e-5;
  setup.options.convergence_optimality_tolerance = 1e-5;
  setup.row_constraints = {0, spec::kSecondObjectiveRow, spec::kSecondObjectiveRow};
  setup.num_constraints = 1;
  setup.traded_constraint = spec::kSecondObjectiveRow;
  setup.traded_sum = form == Form::kSum;
  setup.traded_factors = form == Form::kSum ? std::vector<double>{2.0, 0.25} : std::vector<double>{2.0, 4.0};
  setup.points = kPoints;
  return setup;
}

std::function<AnalysisRecord(const slp::AnalysisRequest&)> Answer(Form form) {
  return [form](const slp::AnalysisRequest& request) {
    const Eigen::VectorXd& x = request.x;
    AnalysisRecord record;
    record.request_id = request.id;
    record.x_scaled.assign(x.data(), x.data() + x.size());
    record.objective_terms = {F1(x)};
    const double d1 = x[0] - 2, d2 = x[1] - 2;
    if (form == Form::kSum) {
      record.constraint_values = {x[0] + x[1], (d1 * d1 + 0.5) / 2, 4 * (d2 * d2 + 0.5)};
    } else {
      record.constraint_values = {x[0] + x[1], F2(x) / 2, (F2(x) - 0.5) / 4};
    }
    if (request.want_gradients) {
      record.objective_gradients = {2 * (x[0] - 1), 2 * (x[1] - 1)};
      if (form == Form::kSum) {
        record.constraint_gradients = {1, 1, d1, 0, 0, 8 * d2};
      } else {
        record.constraint_gradients = {1, 1, d1, d2, d1 / 2, d2 / 2};
      }
    }
    return record;
  };
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

// Drives the front as `workers` workers would (pareto_run_test.cc's
// RunFront); `stop_after` > 0 stops it after that many results, which
// `logged` then holds.
std::vector<std::string> RunFront(Form form, int workers, unsigned seed, std::vector<slp::CycleRecord>* out,
                                  int stop_after = 0, std::vector<AnalysisRecord>* logged = nullptr) {
  absl::StatusOr<std::unique_ptr<ParetoRun>> run =
      ParetoRun::Create(TwoSpheres(form), [] { return lp::MakeClpLpSolver(); });
  EXPECT_TRUE(run.ok()) << run.status();
  if (!run.ok()) return {};
  const auto answer = Answer(form);
  std::mt19937 random(seed);
  std::vector<std::string> encoded;
  int results = 0;
  for (int round = 0; round < kMaxRounds && !(*run)->done(); ++round) {
    std::vector<slp::AnalysisRequest> pending = (*run)->PendingRequests();
    EXPECT_FALSE(pending.empty()) << "the front is not done but asks for nothing";
    if (pending.empty()) break;
    std::shuffle(pending.begin(), pending.end(), random);
    if (static_cast<int>(pending.size()) > workers) pending.resize(static_cast<size_t>(workers));
    for (const slp::AnalysisRequest& request : pending) {
      if (stop_after > 0 && results == stop_after) return encoded;
      const AnalysisRecord record = answer(request);
      EXPECT_TRUE((*run)->Submit(record).ok());
      ++results;
      if (logged != nullptr) logged->push_back(record);
      for (slp::CycleRecord& r : (*run)->TakeNewRecords()) {
        encoded.push_back(EncodeCycleRecord(r));
        if (out != nullptr && r.pareto) out->push_back(std::move(r));
      }
    }
  }
  EXPECT_TRUE((*run)->done());
  return encoded;
}

void ExpectTheClosedFormFront(Form form) {
  std::vector<slp::CycleRecord> records;
  RunFront(form, /*workers=*/4, /*seed=*/1, &records);
  ASSERT_EQ(records.size(), static_cast<size_t>(kPoints));
  double largest_distance = 0;
  for (int k = 0; k < kPoints; ++k) {
    const slp::CycleRecord& r = records[static_cast<size_t>(k)];
    SCOPED_TRACE(::testing::Message() << "point " << k + 1 << " (" << r.pareto_state << ")");
    largest_distance = std::max(largest_distance, std::abs(F1(r.x0) - FrontF1(F2(r.x0))));
    EXPECT_TRUE(r.accepted) << r.rejection_reason;
    const double f1 = F1(r.x0);
    const double f2 = F2(r.x0);
    EXPECT_DOUBLE_EQ(r.objective_x0, f1);
    // The second objective as its rows and factors make it.
    EXPECT_NEAR(r.pareto_value_si, f2, 1e-12);
    EXPECT_NEAR(f1, FrontF1(f2), kFrontTolerance) << "f2 = " << f2;
    if (k > 0 && k + 1 < kPoints) {
      const double level =
          spec::ParetoLevel(k, kPoints, records.front().pareto_value_si, records.back().pareto_value_si);
      EXPECT_EQ(r.pareto_level_si, level);
      EXPECT_LE(r.pareto_value_si, level * (1 + 1e-5));
    }
  }
  std::cout << "largest distance in f1 from the closed-form front: " << largest_distance << "\n";
  // The anchors: f1's optimum at a (f2 = 3 there) and f2's at b (f1 = 3).
  EXPECT_NEAR(records.front().objective_x0, 1.0, kAnchorTolerance);
  EXPECT_NEAR(records.front().pareto_value_si, 3.0, kAnchorTolerance);
  EXPECT_NEAR(records.back().pareto_value_si, 1.0, kAnchorTolerance);
  EXPECT_NEAR(records.back().objective_x0, 3.0, kAnchorTolerance);
}

TEST(ParetoSecondObjective, AWeightedSumReproducesTheClosedFormFront) { ExpectTheClosedFormFront(Form::kSum); }

TEST(ParetoSecondObjective, ALargestOfWeightedRowsReproducesTheClosedFormFront) {
  ExpectTheClosedFormFront(Form::kLargest);
}

TEST(ParetoSecondObjective, SameRecordsWhateverTheWorkersAndTheOrderOfResults) {
  for (Form form : {Form::kSum, Form::kLargest}) {
    const std::vector<std::string> one = RunFront(form, 1, 7, nullptr);
    ASSERT_EQ(PointsIn(one), static_cast<size_t>(kPoints));
    EXPECT_EQ(RunFront(form, 3, 11, nullptr), one);
    EXPECT_EQ(RunFront(form, 64, 12345, nullptr), one);
  }
}

// A resumed job is a new ParetoRun given the logged results again in their
// order; it must then go on as the first one would have.
TEST(ParetoSecondObjective, AFrontResumedFromItsLoggedResultsEndsTheSame) {
  for (Form form : {Form::kSum, Form::kLargest}) {
    const std::vector<std::string> reference = RunFront(form, 3, 21, nullptr);
    ASSERT_EQ(PointsIn(reference), static_cast<size_t>(kPoints));
    std::vector<AnalysisRecord> logged;
    const std::vector<std::string> before = RunFront(form, 3, 21, nullptr, /*stop_after=*/60, &logged);
    ASSERT_EQ(logged.size(), 60u);
    ASSERT_LT(PointsIn(before), static_cast<size_t>(kPoints));
    absl::StatusOr<std::unique_ptr<ParetoRun>> resumed =
        ParetoRun::Create(TwoSpheres(form), [] { return lp::MakeClpLpSolver(); });
    ASSERT_TRUE(resumed.ok()) << resumed.status();
    std::vector<std::string> replayed;
    for (const AnalysisRecord& record : logged) {
      ASSERT_TRUE((*resumed)->Submit(record).ok());
      for (slp::CycleRecord& r : (*resumed)->TakeNewRecords()) replayed.push_back(EncodeCycleRecord(r));
    }
    EXPECT_EQ(replayed, before);
    const auto answer = Answer(form);
    for (int round = 0; round < kMaxRounds && !(*resumed)->done(); ++round) {
      for (const slp::AnalysisRequest& request : (*resumed)->PendingRequests()) {
        ASSERT_TRUE((*resumed)->Submit(answer(request)).ok());
        for (slp::CycleRecord& r : (*resumed)->TakeNewRecords()) replayed.push_back(EncodeCycleRecord(r));
      }
    }
    EXPECT_EQ(replayed, reference);
  }
}

TEST(ParetoSecondObjective, ALargestNeedsFactorsAboveZero) {
  ParetoSetup setup = TwoSpheres(Form::kLargest);
  setup.traded_factors = {2.0, -1.0};
  absl::StatusOr<std::unique_ptr<ParetoRun>> run =
      ParetoRun::Create(std::move(setup), [] { return lp::MakeClpLpSolver(); });
  ASSERT_FALSE(run.ok());
  EXPECT_EQ(run.status().message(),
            "a factor of the second objective's rows is -1; a largest of values needs factors above 0");
}

}  // namespace
}  // namespace mbopt::jobs
