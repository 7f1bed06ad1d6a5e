// A job of a design set (a sweep) driven directly: every design is asked for
// at once, records come out in the designs' order whatever the order of the
// results, and a replay of part of the log leaves only the rest pending.
#include <algorithm>
#include <cmath>
#include <memory>
#include <random>

#include <gtest/gtest.h>

#include "server/jobs/job.h"
#include "server/jobs/record_codec.h"
#include "server/lp/make_clp_lp_solver.h"
#include "spec/io/study_io.h"
#include "tests/server/test_study.h"

namespace mbopt::jobs {
namespace {

// x1 from 0.5 to 2.5 in 5 designs, x2 at its initial 2: defl = x1^2 + 4 is
// F, acc = x1 + 2 >= 2 the constraint (row -acc <= -2, scale 2).
v1::Study SweepStudy() {
  v1::Study proto = testing::OscillatorStudy("oscillator sweep");
  v1::SweepAxis* axis = proto.mutable_sweep()->add_axis();
  axis->set_variable("x1");
  axis->set_from(0.5);
  axis->set_to(2.5);
  axis->set_points(5);
  return proto;
}

std::unique_ptr<Job> NewJob(const v1::Study& proto) {
  absl::StatusOr<spec::Study> study = spec::io::StudyFromProto(proto, "test");
  EXPECT_TRUE(study.ok()) << study.status();
  absl::StatusOr<std::unique_ptr<Job>> job = Job::Create(*study, lp::MakeClpLpSolver());
  EXPECT_TRUE(job.ok()) << job.status();
  return job.ok() ? *std::move(job) : nullptr;
}

// The analytic result of a request; designs listed in `failing` fail.
AnalysisRecord Answer(const v1::Study& proto, const slp::AnalysisRequest& request,
                      const std::vector<std::int64_t>& failing = {}) {
  AnalysisRecord record;
  record.request_id = request.id;
  if (std::find(failing.begin(), failing.end(), request.id) != failing.end()) {
    record.failure = spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, "step size too small");
    return record;
  }
  const std::vector<double> x(request.x.data(), request.x.data() + request.x.size());
  absl::StatusOr<testing::FakeValues> values = testing::EvaluateAnalytically(proto, x);
  EXPECT_TRUE(values.ok()) << values.status();
  record.objective_terms = values->objective_terms;
  record.constraint_values = values->constraint_values;
  return record;
}

struct Logged {
  std::vector<AnalysisRecord> analyses;
  std::vector<std::string> records;
};

// Answers every pending design in the order `order` puts them, logging.
Logged Drive(Job& job, const v1::Study& proto, std::uint64_t shuffle_seed, const std::vector<std::int64_t>& failing = {},
             std::size_t stop_after = SIZE_MAX) {
  Logged log;
  std::vector<slp::AnalysisRequest> pending = job.PendingRequests();
  if (shuffle_seed != 0) std::shuffle(pending.begin(), pending.end(), std::mt19937_64(shuffle_seed));
  for (const slp::AnalysisRequest& request : pending) {
    if (log.analyses.size() == stop_after) break;
    absl::StatusOr<AnalysisRecord> record = job.Intake(Answer(proto, request, failing));
    EXPECT_TRUE(record.ok()) << record.status();
    absl::StatusOr<std::vector<slp::CycleRecord>> records = job.Apply(*record);
    EXPECT_TRUE(records.ok()) << records.status();
    for (const slp::CycleRecord& r : *records) log.records.push_back(EncodeCycleRecord(r));
    log.analyses.push_back(*std::move(record));
  }
  return log;
}

TEST(DesignSetJob, AsksForEveryDesignAtOnce) {
  const v1::Study proto = SweepStudy();
  std::unique_ptr<Job> job = NewJob(proto);
  ASSERT_NE(job, nullptr);
  EXPECT_TRUE(job->is_design_set());
  const std::vector<slp::AnalysisRequest> pending = job->PendingRequests();
  ASSERT_EQ(pending.size(), 5u);
  for (size_t i = 0; i < pending.size(); ++i) {
    EXPECT_EQ(pending[i].id, static_cast<std::int64_t>(i));
    EXPECT_EQ(pending[i].x[0], 0.5 + 0.5 * static_cast<double>(i));
    EXPECT_EQ(pending[i].x[1], 2.0);
    EXPECT_FALSE(pending[i].want_gradients);
  }
  EXPECT_EQ(job->state(), JobState::kRunning);
}

TEST(DesignSetJob, RecordsFollowTheDesignsWhateverTheOrderOfResults) {
  const v1::Study proto = SweepStudy();
  std::unique_ptr<Job> in_order = NewJob(proto);
  const Logged first = Drive(*in_order, proto, 0);
  EXPECT_EQ(in_order->state(), JobState::kCompleted);
  EXPECT_EQ(in_order->cycles_completed(), 5);
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    std::unique_ptr<Job> shuffled = NewJob(proto);
    const Logged other = Drive(*shuffled, proto, seed);
    EXPECT_EQ(other.records, first.records) << "seed " << seed;
    EXPECT_EQ(shuffled->state(), JobState::kCompleted);
  }
}

TEST(DesignSetJob, RecordHoldsTheDesignsValuesAndEachConstraintsViolation) {
  const v1::Study proto = SweepStudy();
  std::unique_ptr<Job> job = NewJob(proto);
  const Logged log = Drive(*job, proto, 7, /*failing=*/{3});
  ASSERT_EQ(log.records.size(), 5u);
  for (size_t i = 0; i < log.records.size(); ++i) {
    absl::StatusOr<slp::CycleRecord> r = DecodeCycleRecord(log.records[i]);
    ASSERT_TRUE(r.ok()) << r.status();
    const double x1 = 0.5 + 0.5 * static_cast<double>(i);
    EXPECT_TRUE(r->design_set);
    EXPECT_EQ(r->cycle, static_cast<int>(i) + 1);
    EXPECT_EQ(r->x0[0], x1);
    ASSERT_EQ(r->constraint_violations.size(), 1u);
    if (i == 3) {
      EXPECT_FALSE(r->accepted);
      EXPECT_EQ(r->failure_kind, "integrator");
      EXPECT_EQ(r->rejection_reason, "step size too small");
      EXPECT_TRUE(std::isnan(r->objective_x0));
      EXPECT_TRUE(std::isnan(r->constraint_violations[0]));
      continue;
    }
    EXPECT_TRUE(r->accepted);
    EXPECT_EQ(r->failure_kind, "");
    EXPECT_NEAR(r->objective_x0, x1 * x1 + 4.0, 1e-12);
    EXPECT_NEAR(r->constraint_violations[0], -x1 / 2.0, 1e-12);
    EXPECT_EQ(r->max_violation_x0, r->constraint_violations[0]);
  }
  EXPECT_EQ(job->state(), JobState::kCompleted);
  EXPECT_EQ(job->failures_by_kind().at(spec::FailureKind::kIntegrator), 1);
}

TEST(DesignSetJob, ReplayOfPartOfTheLogLeavesOnlyTheRestPendingAndEndsTheSame) {
  const v1::Study proto = SweepStudy();
  std::unique_ptr<Job> whole = NewJob(proto);
  const Logged uninterrupted = Drive(*whole, proto, 11);

  // A run stopped after three results (in shuffled order), then resumed.
  std::unique_ptr<Job> killed = NewJob(proto);
  const Logged before = Drive(*killed, proto, 5, {}, 3);
  std::unique_ptr<Job> resumed = NewJob(proto);
  absl::StatusOr<std::vector<slp::CycleRecord>> unlogged = resumed->Replay(before.analyses, before.records);
  ASSERT_TRUE(unlogged.ok()) << unlogged.status();
  EXPECT_TRUE(unlogged->empty());
  const std::vector<slp::AnalysisRequest> rest = resumed->PendingRequests();
  ASSERT_EQ(rest.size(), 2u);
  for (const AnalysisRecord& done : before.analyses) {
    EXPECT_FALSE(resumed->IsPending(done.request_id)) << "design " << done.request_id << " analysed again";
  }
  const Logged after = Drive(*resumed, proto, 9);
  std::vector<std::string> records = before.records;
  records.insert(records.end(), after.records.begin(), after.records.end());
  EXPECT_EQ(records, uninterrupted.records);
  EXPECT_EQ(resumed->state(), JobState::kCompleted);
}

TEST(DesignSetJob, RecordsOfADesignSetRoundTripAndOptimizationRecordsKeepTheirVersion) {
  slp::CycleRecord optimization;
  optimization.x0 = Eigen::Vector2d(1, 2);
  EXPECT_EQ(EncodeCycleRecord(optimization)[0], 3) << "an optimization's record bytes changed";
  slp::CycleRecord design;
  design.design_set = true;
  design.x0 = Eigen::Vector2d(1, 2);
  design.constraint_violations = {-0.5, std::nan("")};
  design.failure_kind = "";
  const std::string bytes = EncodeCycleRecord(design);
  EXPECT_EQ(bytes[0], 4);
  absl::StatusOr<slp::CycleRecord> back = DecodeCycleRecord(bytes);
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->constraint_violations.size(), 2u);
  EXPECT_EQ(back->constraint_violations[0], -0.5);
  EXPECT_TRUE(std::isnan(back->constraint_violations[1]));
  EXPECT_EQ(EncodeCycleRecord(*back), bytes);
  EXPECT_FALSE(DecodeCycleRecord(bytes.substr(0, bytes.size() - 3)).ok());
}

}  // namespace
}  // namespace mbopt::jobs
