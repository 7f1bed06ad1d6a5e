// A job's optimizer driven directly (no server): the cycle-record byte
// format, and replay of a logged run, which resume relies on.
#include "server/jobs/job.h"

#include <cstring>
#include <limits>

#include <gtest/gtest.h>

#include "common/packed_doubles/packed_doubles.h"

#include "server/jobs/analysis_gradients.h"
#include "server/jobs/job_state.h"
#include "server/jobs/record_codec.h"
#include "server/lp/make_clp_lp_solver.h"
#include "spec/io/study_io.h"
#include "tests/server/test_study.h"

namespace mbopt::jobs {
namespace {

slp::CycleRecord SampleRecord() {
  slp::CycleRecord r;
  r.cycle = 3;
  r.attempt = 1;
  r.accepted = false;
  r.rejection_reason = "maxfout 0.52 > 0.40";
  r.x0 = Eigen::Vector2d(1.0 / 3.0, -0.0);
  r.x_trial = Eigen::Vector2d(0.1, 7e-310);
  r.objective_x0 = 2.5;
  r.objective_trial = std::numeric_limits<double>::quiet_NaN();
  r.objective_predicted = -1e300;
  r.worst_constraint_trial = 4;
  r.worst_approximation_row = -1;
  r.lp_feasible = false;
  r.infeasibility = 0.125;
  r.lp_status = "optimal";
  r.lp_iterations = 17;
  r.rows_screened_in = 2;
  r.move_limits = Eigen::Vector2d(0.2, 0.2);
  r.move_limits_next = Eigen::Vector2d(0.1, 0.1);
  r.on_move_limit = {true, false};
  r.on_bound = {false, true};
  r.analyses_total = 123456789012LL;
  r.converged = false;
  return r;
}

TEST(RecordCodec, RoundTripIsBitExact) {
  const slp::CycleRecord r = SampleRecord();
  const std::string bytes = EncodeCycleRecord(r);
  absl::StatusOr<slp::CycleRecord> back = DecodeCycleRecord(bytes);
  ASSERT_TRUE(back.ok()) << back.status();
  // Equal encodings of the decoded record mean every field survived bit for bit.
  EXPECT_EQ(EncodeCycleRecord(*back), bytes);
  EXPECT_EQ(back->rejection_reason, r.rejection_reason);
  EXPECT_EQ(back->on_bound, r.on_bound);
  EXPECT_EQ(back->analyses_total, r.analyses_total);
  const double x = back->x_trial[1];
  EXPECT_EQ(std::memcmp(&x, &r.x_trial[1], sizeof x), 0);
}

TEST(RecordCodec, RestorationFlagRoundTripsAndVersion2RecordsStillRead) {
  slp::CycleRecord r = SampleRecord();
  r.restoration = true;
  const std::string bytes = EncodeCycleRecord(r);
  absl::StatusOr<slp::CycleRecord> back = DecodeCycleRecord(bytes);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_TRUE(back->restoration);
  // A record as version 2 wrote it: no restoration byte at the end.
  std::string version2 = bytes.substr(0, bytes.size() - 1);
  version2[0] = 2;
  absl::StatusOr<slp::CycleRecord> old = DecodeCycleRecord(version2);
  ASSERT_TRUE(old.ok()) << old.status();
  EXPECT_FALSE(old->restoration);
  EXPECT_EQ(old->analyses_total, r.analyses_total);
}

TEST(RecordCodec, TruncatedOrForeignBytesAreDataLoss) {
  const std::string bytes = EncodeCycleRecord(SampleRecord());
  EXPECT_EQ(DecodeCycleRecord(bytes.substr(0, bytes.size() - 1)).status().code(), absl::StatusCode::kDataLoss);
  EXPECT_EQ(DecodeCycleRecord(bytes + "x").status().code(), absl::StatusCode::kDataLoss);
  EXPECT_EQ(DecodeCycleRecord("\x07garbage").status().code(), absl::StatusCode::kDataLoss);
  EXPECT_EQ(DecodeCycleRecord("").status().code(), absl::StatusCode::kDataLoss);
}

TEST(JobState, NamesRoundTrip) {
  for (int s = 1; s <= 9; ++s) {
    const JobState state = static_cast<JobState>(s);
    EXPECT_EQ(ParseJobState(JobStateName(state)), state);
  }
  EXPECT_FALSE(ParseJobState("SLEEPING").has_value());
}

// A run driven to its end in process, with everything a server would log.
struct LoggedRun {
  std::vector<AnalysisRecord> analyses;
  std::vector<std::string> records;
  slp::RunState state = slp::RunState::kRunning;
  Eigen::VectorXd design;
};

std::unique_ptr<Job> NewJob(const v1::Study& proto, std::unique_ptr<lp::LpSolver> lp = lp::MakeClpLpSolver()) {
  absl::StatusOr<spec::Study> study = spec::io::StudyFromProto(proto, "test");
  EXPECT_TRUE(study.ok()) << study.status();
  absl::StatusOr<std::unique_ptr<Job>> job = Job::Create(*study, std::move(lp));
  EXPECT_TRUE(job.ok()) << job.status();
  return job.ok() ? *std::move(job) : nullptr;
}

// The analytic values (and gradients, when asked) of a request, as a
// worker would send them.
AnalysisRecord AnalyticRecord(const v1::Study& proto, const slp::AnalysisRequest& request) {
  const std::vector<double> x(request.x.data(), request.x.data() + request.x.size());
  AnalysisRecord record;
  record.request_id = request.id;
  absl::StatusOr<testing::FakeValues> values = testing::EvaluateAnalytically(proto, x);
  EXPECT_TRUE(values.ok());
  record.objective_terms = values->objective_terms;
  record.constraint_values = values->constraint_values;
  if (request.want_gradients) {
    absl::StatusOr<testing::FakeGradients> gradients = testing::GradientsAnalytically(proto, x);
    EXPECT_TRUE(gradients.ok()) << gradients.status();
    record.objective_gradients = gradients->objective_gradients;
    record.constraint_gradients = gradients->constraint_gradients;
  }
  return record;
}

LoggedRun RunAndLog(const v1::Study& proto) {
  LoggedRun run;
  std::unique_ptr<Job> job = NewJob(proto);
  while (true) {
    std::vector<slp::AnalysisRequest> pending = job->PendingRequests();
    if (pending.empty()) break;
    // Answer the batch last-first, to differ from the replay's order.
    for (auto it = pending.rbegin(); it != pending.rend(); ++it) {
      absl::StatusOr<AnalysisRecord> record = job->Intake(AnalyticRecord(proto, *it));
      EXPECT_TRUE(record.ok()) << record.status();
      if (it->want_gradients) {
        EXPECT_FALSE(record->objective_gradients.empty()) << record->gradients_unavailable;
      }
      absl::StatusOr<std::vector<slp::CycleRecord>> records = job->Apply(*record);
      EXPECT_TRUE(records.ok()) << records.status();
      for (const slp::CycleRecord& r : *records) run.records.push_back(EncodeCycleRecord(r));
      run.analyses.push_back(*std::move(record));
    }
  }
  run.state = job->optimizer().state();
  run.design = job->optimizer().current_design();
  return run;
}

TEST(JobIntake, FillsTheRequestsDesignPointAndDropsUnaskedGradients) {
  const v1::Study proto = testing::OscillatorStudy();
  std::unique_ptr<Job> job = NewJob(proto);
  const std::vector<slp::AnalysisRequest> pending = job->PendingRequests();
  ASSERT_FALSE(pending.empty());
  ASSERT_FALSE(pending[0].want_gradients);
  AnalysisRecord candidate = AnalyticRecord(proto, pending[0]);
  candidate.objective_gradients.assign(static_cast<size_t>(pending[0].x.size()), 1.0);
  absl::StatusOr<AnalysisRecord> record = job->Intake(candidate);
  ASSERT_TRUE(record.ok()) << record.status();
  ASSERT_EQ(record->x_scaled.size(), static_cast<size_t>(pending[0].x.size()));
  EXPECT_EQ(std::memcmp(record->x_scaled.data(), pending[0].x.data(), sizeof(double) * record->x_scaled.size()), 0);
  EXPECT_TRUE(record->objective_gradients.empty());
}

TEST(JobIntake, NonFiniteValueBecomesAFailureOfThatKind) {
  const v1::Study proto = testing::OscillatorStudy();
  std::unique_ptr<Job> job = NewJob(proto);
  AnalysisRecord candidate = AnalyticRecord(proto, job->PendingRequests()[0]);
  ASSERT_FALSE(candidate.constraint_values.empty());
  candidate.constraint_values[0] = std::numeric_limits<double>::infinity();
  absl::StatusOr<AnalysisRecord> record = job->Intake(candidate);
  ASSERT_TRUE(record.ok()) << record.status();
  EXPECT_EQ(record->failure.kind, spec::FailureKind::kNonFiniteValue);
  EXPECT_NE(record->failure.reason.find("constraint value 0"), std::string::npos) << record->failure.reason;
  EXPECT_TRUE(record->constraint_values.empty());
}

// A worker's packed values are unpacked at intake, bit for bit, and kept
// packed for the log; a packing of more values than the study has, or values
// sent both ways, is refused.
TEST(JobIntake, PackedValuesAreUnpackedAndCheckedAgainstTheStudy) {
  const v1::Study proto = testing::OscillatorStudy();
  std::unique_ptr<Job> job = NewJob(proto);
  const AnalysisRecord analytic = AnalyticRecord(proto, job->PendingRequests()[0]);
  AnalysisRecord candidate = analytic;
  candidate.objective_terms_packed = packed::PackDoubles(candidate.objective_terms);
  candidate.constraint_values_packed = packed::PackDoubles(candidate.constraint_values);
  AnalysisRecord sent_both_ways = candidate;
  candidate.objective_terms.clear();
  candidate.constraint_values.clear();
  absl::StatusOr<AnalysisRecord> record = job->Intake(candidate);
  ASSERT_TRUE(record.ok()) << record.status();
  ASSERT_EQ(record->constraint_values.size(), analytic.constraint_values.size());
  EXPECT_EQ(std::memcmp(record->constraint_values.data(), analytic.constraint_values.data(),
                        sizeof(double) * analytic.constraint_values.size()),
            0);
  EXPECT_EQ(record->constraint_values_packed, candidate.constraint_values_packed);

  EXPECT_EQ(job->Intake(sent_both_ways).status().code(), absl::StatusCode::kInvalidArgument);
  AnalysisRecord too_many = candidate;
  std::vector<double> more = analytic.constraint_values;
  more.push_back(1.0);
  too_many.constraint_values_packed = packed::PackDoubles(more);
  const absl::Status refused = job->Intake(too_many).status();
  EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(refused.message().find("constraint values"), std::string::npos) << refused;
  AnalysisRecord damaged = candidate;
  damaged.constraint_values_packed.resize(damaged.constraint_values_packed.size() / 2);
  EXPECT_EQ(job->Intake(damaged).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(JobIntake, WrongSizeOrUnknownRequestIsRefused) {
  const v1::Study proto = testing::OscillatorStudy();
  std::unique_ptr<Job> job = NewJob(proto);
  AnalysisRecord candidate = AnalyticRecord(proto, job->PendingRequests()[0]);
  candidate.constraint_values.push_back(1.0);
  EXPECT_EQ(job->Intake(candidate).status().code(), absl::StatusCode::kInvalidArgument);
  AnalysisRecord unknown = AnalyticRecord(proto, job->PendingRequests()[0]);
  unknown.request_id = 999'999;
  EXPECT_EQ(job->Intake(unknown).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(JobIntake, FailedAnalysesAreCountedByKind) {
  const v1::Study proto = testing::OscillatorStudy();
  std::unique_ptr<Job> job = NewJob(proto);
  AnalysisRecord failed;
  failed.request_id = job->PendingRequests()[0].id;
  failed.failure = spec::AnalysisFailure::Of(spec::FailureKind::kAssembly, "joint B cannot close at t = 0 s");
  absl::StatusOr<AnalysisRecord> record = job->Intake(failed);
  ASSERT_TRUE(record.ok()) << record.status();
  ASSERT_TRUE(job->Apply(*record).ok());
  EXPECT_EQ(job->failures_by_kind().at(spec::FailureKind::kAssembly), 1);
  EXPECT_EQ(job->last_failure().reason, "joint B cannot close at t = 0 s");
}

// An LP solver that fails every solve: a job built with it shows that the
// solver is the injected one (CLP would solve these LPs).
class FailingLpSolver : public lp::LpSolver {
 public:
  lp::LpSolution Solve(const lp::LinearProgram&) override {
    ++solves_;
    lp::LpSolution solution;
    solution.status = lp::LpStatus::kNumericalFailure;
    solution.message = "injected LP failure";
    return solution;
  }
  void ResetWarmStart() override {}
  int solves() const { return solves_; }

 private:
  int solves_ = 0;
};

TEST(JobRun, UsesTheInjectedLpSolver) {
  const v1::Study proto = testing::OscillatorStudy();
  auto lp = std::make_unique<FailingLpSolver>();
  const FailingLpSolver* solver = lp.get();
  std::unique_ptr<Job> job = NewJob(proto, std::move(lp));
  FunctionEvaluator evaluator([&proto](const slp::AnalysisRequest& request) { return AnalyticRecord(proto, request); });
  JobRunOptions options;
  options.max_analyses = 1'000;
  ASSERT_TRUE(job->Run(evaluator, options).ok());
  EXPECT_GT(solver->solves(), 0);
  EXPECT_NE(job->optimizer().state(), slp::RunState::kConverged);
}

TEST(JobRun, EndsAsTheStepByStepDriveDoes) {
  const v1::Study proto = testing::OscillatorStudy();
  const LoggedRun stepwise = RunAndLog(proto);
  std::unique_ptr<Job> job = NewJob(proto);
  FunctionEvaluator evaluator([&proto](const slp::AnalysisRequest& request) { return AnalyticRecord(proto, request); });
  std::vector<std::string> records;
  JobRunOptions options;
  options.on_record = [&records](const slp::CycleRecord& r) { records.push_back(EncodeCycleRecord(r)); };
  ASSERT_TRUE(job->Run(evaluator, options).ok());
  ASSERT_FALSE(records.empty());
  EXPECT_EQ(records, stepwise.records);
  EXPECT_EQ(job->optimizer().state(), stepwise.state);
}

TEST(JobReplay, ReplayOfAWholeRunRebuildsTheFinalState) {
  const v1::Study proto = testing::OscillatorStudy();
  LoggedRun run = RunAndLog(proto);
  ASSERT_EQ(run.state, slp::RunState::kConverged);
  std::unique_ptr<Job> job = NewJob(proto);
  absl::StatusOr<std::vector<slp::CycleRecord>> unlogged = job->Replay(run.analyses, run.records);
  ASSERT_TRUE(unlogged.ok()) << unlogged.status();
  EXPECT_TRUE(unlogged->empty());
  EXPECT_EQ(job->optimizer().state(), slp::RunState::kConverged);
  EXPECT_TRUE(job->PendingRequests().empty());
  ASSERT_EQ(job->optimizer().current_design().size(), run.design.size());
  EXPECT_EQ(std::memcmp(job->optimizer().current_design().data(), run.design.data(),
                        sizeof(double) * static_cast<size_t>(run.design.size())),
            0);
}

TEST(JobReplay, ReplayWithGradientsRebuildsTheFinalState) {
  const v1::Study proto = testing::OscillatorStudyWithSensitivities();
  LoggedRun run = RunAndLog(proto);
  ASSERT_EQ(run.state, slp::RunState::kConverged);
  // Gradients from every analysis: one for x0, then one per trial (record).
  EXPECT_EQ(run.analyses.size(), run.records.size() + 1);
  std::unique_ptr<Job> job = NewJob(proto);
  absl::StatusOr<std::vector<slp::CycleRecord>> unlogged = job->Replay(run.analyses, run.records);
  ASSERT_TRUE(unlogged.ok()) << unlogged.status();
  EXPECT_TRUE(unlogged->empty());
  EXPECT_EQ(job->optimizer().state(), slp::RunState::kConverged);
  ASSERT_EQ(job->optimizer().current_design().size(), run.design.size());
  EXPECT_EQ(std::memcmp(job->optimizer().current_design().data(), run.design.data(),
                        sizeof(double) * static_cast<size_t>(run.design.size())),
            0);
}

// A problem with 2 variables, 1 objective term and 3 constraint rows.
slp::ProblemSpec ThreeRowProblem() {
  slp::ProblemSpec problem;
  problem.lower = Eigen::Vector2d(0, 0);
  problem.upper = Eigen::Vector2d(1, 1);
  problem.initial = Eigen::Vector2d(0.5, 0.5);
  problem.variable_names = {"a", "b"};
  problem.num_objective_terms = 1;
  problem.constraint_names = {"r0", "r1", "r2"};
  problem.constraint_limits = Eigen::Vector3d(1, 1, 1);
  problem.constraint_scales = Eigen::Vector3d(1, 1, 1);
  return problem;
}

TEST(AnalysisGradients, RowMajorVectorsBecomeTheResultsMatrices) {
  const slp::ProblemSpec problem = ThreeRowProblem();
  EXPECT_EQ(GradientDefect(problem, {1, 2}, {3, 4, 5, 6, 7, 8}), "");
  slp::AnalysisResult result;
  AttachGradients(problem, {1, 2}, {3, 4, 5, 6, 7, 8}, &result);
  ASSERT_TRUE(result.has_gradients());
  ASSERT_EQ(result.objective_gradients.rows(), 1);
  ASSERT_EQ(result.objective_gradients.cols(), 2);
  EXPECT_EQ(result.objective_gradients(0, 1), 2);
  ASSERT_EQ(result.constraint_gradients.rows(), 3);
  ASSERT_EQ(result.constraint_gradients.cols(), 2);
  EXPECT_EQ(result.constraint_gradients(1, 0), 5);  // row r1, variable a
  EXPECT_EQ(result.constraint_gradients(2, 1), 8);
}

TEST(AnalysisGradients, EmptyIsNoGradientsAndNoDefect) {
  const slp::ProblemSpec problem = ThreeRowProblem();
  EXPECT_EQ(GradientDefect(problem, {}, {}), "");
  slp::AnalysisResult result;
  AttachGradients(problem, {}, {}, &result);
  EXPECT_FALSE(result.has_gradients());
}

TEST(AnalysisGradients, WrongSizeOrNonFiniteEntryIsADefectAndGivesNoGradients) {
  const slp::ProblemSpec problem = ThreeRowProblem();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  struct Case {
    std::vector<double> objective, constraints;
    const char* mentions;
  };
  for (const Case& c : {Case{{1, 2}, {3, 4, 5, 6, 7}, "expected"}, Case{{1}, {3, 4, 5, 6, 7, 8}, "expected"},
                        Case{{}, {3, 4, 5, 6, 7, 8}, "expected"}, Case{{1, nan}, {3, 4, 5, 6, 7, 8}, "objective"},
                        Case{{1, 2}, {3, 4, 5, 6, -inf, 8}, "r2"}}) {
    const std::string defect = GradientDefect(problem, c.objective, c.constraints);
    EXPECT_NE(defect.find(c.mentions), std::string::npos) << defect;
    slp::AnalysisResult result;
    AttachGradients(problem, c.objective, c.constraints, &result);
    EXPECT_FALSE(result.has_gradients()) << defect;
    EXPECT_EQ(result.constraint_gradients.size(), 0);
  }
}

TEST(JobReplay, RecordsMissingFromTheLogAreReturnedForLogging) {
  // A crash after an analysis was committed but before its cycle's records.
  const v1::Study proto = testing::OscillatorStudy();
  LoggedRun run = RunAndLog(proto);
  ASSERT_GE(run.records.size(), 2u);
  const size_t kept = run.records.size() - 1;
  std::vector<std::string> logged(run.records.begin(), run.records.begin() + static_cast<std::ptrdiff_t>(kept));
  std::unique_ptr<Job> job = NewJob(proto);
  absl::StatusOr<std::vector<slp::CycleRecord>> unlogged = job->Replay(run.analyses, logged);
  ASSERT_TRUE(unlogged.ok()) << unlogged.status();
  ASSERT_EQ(unlogged->size(), 1u);
  EXPECT_EQ(EncodeCycleRecord(unlogged->front()), run.records.back());
}

TEST(JobReplay, PartialLogLeavesOnlyTheMissingAnalysesPending) {
  const v1::Study proto = testing::OscillatorStudy();
  LoggedRun run = RunAndLog(proto);
  std::unique_ptr<Job> reference = NewJob(proto);
  const size_t kept = run.analyses.size() / 2;
  std::vector<AnalysisRecord> half(run.analyses.begin(), run.analyses.begin() + static_cast<std::ptrdiff_t>(kept));
  std::unique_ptr<Job> job = NewJob(proto);
  absl::StatusOr<std::vector<slp::CycleRecord>> unlogged = job->Replay(half, {});
  ASSERT_TRUE(unlogged.ok()) << unlogged.status();
  for (const slp::AnalysisRequest& request : job->PendingRequests()) {
    for (const AnalysisRecord& a : half) EXPECT_NE(a.request_id, request.id);
  }
  EXPECT_FALSE(job->PendingRequests().empty());
}

TEST(JobReplay, DifferingRecordIsDataLoss) {
  const v1::Study proto = testing::OscillatorStudy();
  LoggedRun run = RunAndLog(proto);
  ASSERT_FALSE(run.records.empty());
  absl::StatusOr<slp::CycleRecord> first = DecodeCycleRecord(run.records[0]);
  ASSERT_TRUE(first.ok());
  first->objective_x0 = std::nextafter(first->objective_x0, 1e300);
  run.records[0] = EncodeCycleRecord(*first);
  std::unique_ptr<Job> job = NewJob(proto);
  absl::StatusOr<std::vector<slp::CycleRecord>> unlogged = job->Replay(run.analyses, run.records);
  EXPECT_EQ(unlogged.status().code(), absl::StatusCode::kDataLoss);
}

TEST(JobReplay, DifferingDesignPointIsDataLoss) {
  const v1::Study proto = testing::OscillatorStudy();
  LoggedRun run = RunAndLog(proto);
  run.analyses[0].x_scaled[0] += 1e-12;
  std::unique_ptr<Job> job = NewJob(proto);
  EXPECT_EQ(job->Replay(run.analyses, run.records).status().code(), absl::StatusCode::kDataLoss);
}

TEST(JobReplay, MoreLoggedRecordsThanTheReplayGivesIsDataLoss) {
  const v1::Study proto = testing::OscillatorStudy();
  LoggedRun run = RunAndLog(proto);
  run.records.push_back(run.records.back());
  std::unique_ptr<Job> job = NewJob(proto);
  EXPECT_EQ(job->Replay(run.analyses, run.records).status().code(), absl::StatusCode::kDataLoss);
}

}  // namespace
}  // namespace mbopt::jobs
