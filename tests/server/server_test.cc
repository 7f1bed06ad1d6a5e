// The optimizer server in process: real gRPC services, store and scheduler
// on a temporary database, a fake clock for leases, and fake workers that
// answer with closed-form values (test_study.h).
#include "server/service/server.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <google/protobuf/unknown_field_set.h>
#include <gmock/gmock.h>
#include <grpcpp/generic/generic_stub.h>
#include <gtest/gtest.h>

#include "absl/cleanup/cleanup.h"
#include "absl/strings/str_cat.h"
#include "mbopt/v1/service.grpc.pb.h"
#include "server/scheduler/clock.h"
#include "server/scheduler/scheduler.h"
#include "server/service/grpc_services.h"
#include "server/service/listen_address.h"
#include "server/store/store.h"
#include "tests/server/fake_worker.h"
#include "tests/server/test_study.h"

namespace mbopt::service {
namespace {

using ::mbopt::testing::FakeWorker;
using ::mbopt::testing::OscillatorStudy;
using ::mbopt::testing::OscillatorStudyWithSensitivities;
using ::testing::HasSubstr;

constexpr std::int64_t kLeaseMs = 10'000;
// The analytic problem's optimum is x = (1, 1); the SLP stops within its
// relative objective tolerance (0.5 %), which allows a design error of the
// order of sqrt(0.005) on this quadratic; 0.05 is a loose bound on that.
constexpr double kDesignTolerance = 0.05;

class ServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("mbopt_server_") + info->name() + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::unique_ptr<MboptServer> StartServer(const std::string& db_name, jobs::manager::JobManagerOptions manager = {}) {
    ServerOptions options;
    options.listen_address = "127.0.0.1:0";
    options.db_path = (dir_ / db_name).string();
    options.lease_ms = kLeaseMs;
    options.heartbeat_ms = kLeaseMs / 4;
    options.clock = &clock_;
    options.manager = std::move(manager);
    absl::StatusOr<std::unique_ptr<MboptServer>> server = MboptServer::Start(options);
    EXPECT_TRUE(server.ok()) << server.status();
    return server.ok() ? *std::move(server) : nullptr;
  }

  // The call's status; the new job's id in *job_id when it succeeds.
  static grpc::Status TrySubmit(MboptServer& server, const v1::Study& study, std::string* job_id = nullptr) {
    return TrySubmitFrom(server, study, study.name() + ".study.textproto", job_id);
  }
  // The same as sent from the file `source_name` ("": none given).
  static grpc::Status TrySubmitFrom(MboptServer& server, const v1::Study& study, const std::string& source_name,
                                    std::string* job_id = nullptr) {
    auto stub = v1::JobService::NewStub(server.InProcessChannel());
    grpc::ClientContext context;
    v1::SubmitJobRequest request;
    request.set_study(study.SerializeAsString());
    if (!source_name.empty()) request.set_source_name(source_name);
    v1::SubmitJobResponse response;
    grpc::Status status = stub->Submit(&context, request, &response);
    if (job_id != nullptr) *job_id = response.job_id();
    return status;
  }
  static std::string Submit(MboptServer& server, const v1::Study& study) {
    std::string job_id;
    grpc::Status status = TrySubmit(server, study, &job_id);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return job_id;
  }

  static v1::GetJobResponse Get(MboptServer& server, const std::string& job_id) {
    auto stub = v1::JobService::NewStub(server.InProcessChannel());
    grpc::ClientContext context;
    v1::JobRef ref;
    ref.set_job_id(job_id);
    v1::GetJobResponse response;
    grpc::Status status = stub->Get(&context, ref, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return response;
  }

  // Runs the study to its end on a fresh database; returns the final Get.
  // `answer_order`: the request ids in the order the worker answered them.
  v1::GetJobResponse RunToEnd(const std::string& db_name, std::uint32_t seed,
                              const v1::Study& study = OscillatorStudy(),
                              std::vector<std::int64_t>* answer_order = nullptr) {
    auto server = StartServer(db_name);
    const std::string id = Submit(*server, study);
    FakeWorker worker(server->InProcessChannel(), seed);
    worker.Run();
    if (answer_order != nullptr) *answer_order = worker.answered_request_ids();
    return Get(*server, id);
  }

  scheduler::FakeClock clock_;
  std::filesystem::path dir_;
};

// Records compared as bytes: bit-identical doubles or a failure.
void ExpectSameCycles(const v1::GetJobResponse& a, const v1::GetJobResponse& b) {
  ASSERT_EQ(a.cycles_size(), b.cycles_size());
  for (int i = 0; i < a.cycles_size(); ++i) {
    EXPECT_EQ(a.cycles(i).SerializeAsString(), b.cycles(i).SerializeAsString()) << "record " << i;
  }
  ASSERT_EQ(a.summary().design_size(), b.summary().design_size());
  for (int i = 0; i < a.summary().design_size(); ++i) {
    const double da = a.summary().design(i), db = b.summary().design(i);
    EXPECT_EQ(std::memcmp(&da, &db, sizeof da), 0) << "design " << i << ": " << da << " vs " << db;
  }
}

TEST_F(ServerTest, SubmittedStudyConvergesToTheAnalyticOptimum) {
  v1::GetJobResponse job = RunToEnd("a.db", 1);
  EXPECT_EQ(job.summary().state(), v1::JOB_STATE_CONVERGED) << job.summary().message();
  ASSERT_EQ(job.summary().design_size(), 2);
  EXPECT_NEAR(job.summary().design(0) / testing::kStiffnessScale, 1.0, kDesignTolerance);
  EXPECT_NEAR(job.summary().design(1) / testing::kDampingScale, 1.0, kDesignTolerance);
  EXPECT_EQ(job.summary().design_names(0), "x1");
  EXPECT_EQ(job.summary().design_units(0), "N/m");
  EXPECT_GT(job.cycles_size(), 0);
  EXPECT_TRUE(job.cycles(job.cycles_size() - 1).converged());
  EXPECT_EQ(job.summary().cycles(), job.cycles(job.cycles_size() - 1).cycle());
  EXPECT_EQ(job.study().name(), "oscillator");
  // Physical trial design = scale * scaled.
  const v1::CycleRecord& last = job.cycles(job.cycles_size() - 1);
  EXPECT_EQ(last.x_trial_physical(0), testing::kStiffnessScale * last.x_trial_scaled(0));
}

// The same study, answered in two different orders (the fake worker
// shuffles with its seed), gives the same records bit for bit. Both runs
// must have run to convergence and answered in different orders, or the
// comparison would prove nothing.
TEST_F(ServerTest, ResultsDoNotDependOnTheOrderOfAnswers) {
  std::vector<std::int64_t> first_order, second_order;
  v1::GetJobResponse first = RunToEnd("a.db", 1, OscillatorStudy(), &first_order);
  v1::GetJobResponse second = RunToEnd("b.db", 12345, OscillatorStudy(), &second_order);
  for (const v1::GetJobResponse* job : {&first, &second}) {
    ASSERT_EQ(job->summary().state(), v1::JOB_STATE_CONVERGED) << job->summary().message();
    ASSERT_GT(job->cycles_size(), 1) << "a run of one cycle does not depend on any order";
    EXPECT_TRUE(job->cycles(job->cycles_size() - 1).converged());
  }
  ASSERT_FALSE(first_order.empty());
  ASSERT_NE(first_order, second_order) << "both runs answered in the same order";
  ExpectSameCycles(first, second);
}

TEST_F(ServerTest, ConcurrentWorkersGiveTheSameResultAsOne) {
  v1::GetJobResponse reference = RunToEnd("reference.db", 7);
  auto server = StartServer("concurrent.db");
  const std::string first = Submit(*server, OscillatorStudy("first"));
  const std::string second = Submit(*server, OscillatorStudy("second"));
  std::atomic<bool> stop{false};
  // Each long poll returns within this bound once the jobs have ended; it
  // is not a wait for anything to happen.
  constexpr int kPollMs = 100;
  std::vector<std::thread> workers;
  for (std::uint32_t seed = 20; seed < 24; ++seed) {
    workers.emplace_back([&, seed] {
      FakeWorker worker(server->InProcessChannel(), seed);
      worker.RunUntil(stop, kPollMs);
    });
  }
  auto stub = v1::JobService::NewStub(server->InProcessChannel());
  for (const std::string& id : {first, second}) {
    grpc::ClientContext context;
    v1::JobRef ref;
    ref.set_job_id(id);
    auto reader = stub->Watch(&context, ref);
    v1::JobEvent event;
    while (reader->Read(&event)) {
    }
    EXPECT_TRUE(reader->Finish().ok());
  }
  stop = true;
  for (std::thread& t : workers) t.join();
  for (const std::string& id : {first, second}) {
    v1::GetJobResponse job = Get(*server, id);
    EXPECT_EQ(job.summary().state(), v1::JOB_STATE_CONVERGED) << id;
    ExpectSameCycles(reference, job);
  }
}

TEST_F(ServerTest, RestartAfterCrashResumesBitIdentically) {
  v1::GetJobResponse reference = RunToEnd("reference.db", 7);
  ASSERT_EQ(reference.summary().state(), v1::JOB_STATE_CONVERGED);
  // Stop after a number of results that ends in the middle of a cycle.
  const int kResultsBeforeCrash = 7;
  std::string id;
  {
    auto server = StartServer("crash.db");
    id = Submit(*server, OscillatorStudy());
    FakeWorker worker(server->InProcessChannel(), 99);
    ASSERT_EQ(worker.Run(kResultsBeforeCrash), kResultsBeforeCrash);
    v1::GetJobResponse partial = Get(*server, id);
    ASSERT_EQ(partial.summary().state(), v1::JOB_STATE_RUNNING);
    // Destroyed without Shutdown: the database says RUNNING, as after a crash.
  }
  auto server = StartServer("crash.db");
  v1::GetJobResponse resumed = Get(*server, id);
  EXPECT_EQ(resumed.summary().state(), v1::JOB_STATE_RUNNING);
  FakeWorker worker(server->InProcessChannel(), 3);
  worker.Run();
  v1::GetJobResponse finished = Get(*server, id);
  EXPECT_EQ(finished.summary().state(), v1::JOB_STATE_CONVERGED);
  ExpectSameCycles(reference, finished);
}

// An inspecting server (what `mbopt status --db` starts) on a database whose
// server crashed: the job is shown interrupted and left as it was (no task
// for a worker, no submit, resume or cancel, nothing written); the next real
// server resumes it to the uninterrupted result.
TEST_F(ServerTest, InspectingServerShowsACrashedJobInterruptedAndLeavesItAlone) {
  v1::GetJobResponse reference = RunToEnd("reference.db", 7);
  std::string id;
  {
    auto server = StartServer("crash.db");
    id = Submit(*server, OscillatorStudy());
    FakeWorker worker(server->InProcessChannel(), 99);
    ASSERT_EQ(worker.Run(7), 7);
  }
  {
    jobs::manager::JobManagerOptions inspect;
    inspect.inspect_only = true;
    auto server = StartServer("crash.db", inspect);
    v1::GetJobResponse shown = Get(*server, id);
    EXPECT_EQ(shown.summary().state(), v1::JOB_STATE_INTERRUPTED);
    EXPECT_NE(shown.summary().message().find("server not running"), std::string::npos) << shown.summary().message();
    EXPECT_NE(shown.summary().message().find("mbopt resume " + id + " --db "), std::string::npos);
    FakeWorker worker(server->InProcessChannel(), 3);
    EXPECT_EQ(worker.Run(1), 0) << "an inspecting server hands out no task";
    grpc::Status submitted = TrySubmit(*server, OscillatorStudy());
    EXPECT_EQ(submitted.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << submitted.error_message();
    auto stub = v1::JobService::NewStub(server->InProcessChannel());
    for (bool cancel : {false, true}) {
      grpc::ClientContext context;
      v1::JobRef ref;
      ref.set_job_id(id);
      v1::JobSummary summary;
      grpc::Status status = cancel ? stub->Cancel(&context, ref, &summary) : stub->Resume(&context, ref, &summary);
      EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << status.error_message();
    }
    server->Shutdown();
  }
  {
    auto store = store::Store::Open((dir_ / "crash.db").string());
    ASSERT_TRUE(store.ok()) << store.status();
    auto row = store->get()->GetJob(id);
    ASSERT_TRUE(row.ok());
    EXPECT_EQ(row->state, "RUNNING") << "inspecting wrote nothing";
  }
  auto server = StartServer("crash.db");
  FakeWorker worker(server->InProcessChannel(), 3);
  worker.Run();
  v1::GetJobResponse finished = Get(*server, id);
  EXPECT_EQ(finished.summary().state(), v1::JOB_STATE_CONVERGED);
  ExpectSameCycles(reference, finished);
}

TEST_F(ServerTest, GracefulStopInterruptsAndNextStartResumesBitIdentically) {
  v1::GetJobResponse reference = RunToEnd("reference.db", 7);
  std::string id;
  {
    auto server = StartServer("stop.db");
    id = Submit(*server, OscillatorStudy());
    FakeWorker worker(server->InProcessChannel(), 5);
    worker.Run(11);
    server->Shutdown();
  }
  {
    auto store = store::Store::Open((dir_ / "stop.db").string());
    ASSERT_TRUE(store.ok()) << store.status();
    auto row = (*store)->GetJob(id);
    ASSERT_TRUE(row.ok());
    EXPECT_EQ(row->state, "INTERRUPTED");
  }
  auto server = StartServer("stop.db");
  FakeWorker worker(server->InProcessChannel(), 6);
  worker.Run();
  ExpectSameCycles(reference, Get(*server, id));
}

TEST_F(ServerTest, RestartRightAfterACycleCommitResumesBitIdentically) {
  v1::GetJobResponse reference = RunToEnd("reference.db", 7);
  std::string id;
  std::int64_t records_committed = 0;
  {
    jobs::manager::JobManagerOptions manager;
    manager.after_record_commit = [&records_committed](std::int64_t n) { records_committed = n; };
    auto server = StartServer("hook.db", manager);
    id = Submit(*server, OscillatorStudy());
    FakeWorker worker(server->InProcessChannel(), 8);
    while (records_committed < 2) ASSERT_EQ(worker.Run(1), 1);
  }
  EXPECT_EQ(records_committed, 2);
  auto server = StartServer("hook.db");
  EXPECT_EQ(Get(*server, id).cycles_size(), 2);
  FakeWorker worker(server->InProcessChannel(), 9);
  worker.Run();
  ExpectSameCycles(reference, Get(*server, id));
}

// ---------------------------------------------------- simulator gradients --

// The analysis log of a job (the server must be gone: it holds the lock).
std::vector<jobs::AnalysisRecord> LoggedAnalyses(const std::filesystem::path& db, const std::string& id) {
  auto store = store::Store::Open(db.string());
  EXPECT_TRUE(store.ok()) << store.status();
  if (!store.ok()) return {};
  auto rows = (*store)->LoadAnalyses(id);
  EXPECT_TRUE(rows.ok()) << rows.status();
  return rows.ok() ? *rows : std::vector<jobs::AnalysisRecord>{};
}

TEST_F(ServerTest, SimulatorSensitivityJobTakesGradientsFromItsAnalyses) {
  std::string id;
  v1::GetJobResponse job;
  {
    auto server = StartServer("sens.db");
    id = Submit(*server, OscillatorStudyWithSensitivities());
    FakeWorker worker(server->InProcessChannel(), 1);
    worker.Run();
    job = Get(*server, id);
    EXPECT_EQ(worker.tasks_without_gradients(), 0) << "no finite-difference perturbation was asked for";
    EXPECT_EQ(worker.tasks_wanting_gradients(), job.summary().analyses());
  }
  EXPECT_EQ(job.summary().state(), v1::JOB_STATE_CONVERGED) << job.summary().message();
  ASSERT_EQ(job.summary().design_size(), 2);
  EXPECT_NEAR(job.summary().design(0) / testing::kStiffnessScale, 1.0, kDesignTolerance);
  EXPECT_NEAR(job.summary().design(1) / testing::kDampingScale, 1.0, kDesignTolerance);
  // One analysis of the initial design, then one per trial point (one record
  // each): an accepted trial's gradients linearize the next cycle.
  EXPECT_EQ(job.summary().analyses(), 1 + job.cycles_size());
  const v1::GetJobResponse finite_differences = RunToEnd("fd.db", 1);
  EXPECT_LT(job.summary().analyses(), finite_differences.summary().analyses());

  const std::vector<jobs::AnalysisRecord> logged = LoggedAnalyses(dir_ / "sens.db", id);
  ASSERT_EQ(static_cast<std::int64_t>(logged.size()), job.summary().analyses());
  for (const jobs::AnalysisRecord& row : logged) {
    ASSERT_TRUE(row.ok()) << row.failure.reason;
    // 1 objective term x 2 variables; 1 constraint row x 2 variables.
    EXPECT_EQ(row.objective_gradients.size(), 2u) << "request " << row.request_id;
    EXPECT_EQ(row.constraint_gradients.size(), 2u) << "request " << row.request_id;
    EXPECT_EQ(row.gradients_unavailable, "");
  }
}

// Gradients that are missing, of the wrong size or not finite are no
// gradients: the values count, and every cycle falls back to finite
// differences, which gives exactly the finite-difference run.
TEST_F(ServerTest, MissingOrUnusableGradientsFallBackToFiniteDifferences) {
  const v1::GetJobResponse reference = RunToEnd("fd.db", 1);
  ASSERT_EQ(reference.summary().state(), v1::JOB_STATE_CONVERGED);
  struct Case {
    FakeWorker::GradientMode mode;
    const char* reason;
  };
  for (const Case& c : {Case{FakeWorker::GradientMode::kNone, "this fake worker has no gradients"},
                        Case{FakeWorker::GradientMode::kWrongSize, "unusable gradients"},
                        Case{FakeWorker::GradientMode::kNonFinite, "unusable gradients"}}) {
    const std::string db = absl::StrCat("mode", static_cast<int>(c.mode), ".db");
    std::string id;
    v1::GetJobResponse job;
    {
      auto server = StartServer(db);
      id = Submit(*server, OscillatorStudyWithSensitivities());
      FakeWorker worker(server->InProcessChannel(), 1);
      worker.SetGradientMode(c.mode);
      worker.Run();
      job = Get(*server, id);
      EXPECT_GT(worker.tasks_without_gradients(), 0) << c.reason << ": perturbations were asked for";
    }
    EXPECT_EQ(job.summary().state(), v1::JOB_STATE_CONVERGED) << job.summary().message();
    ExpectSameCycles(reference, job);
    int without = 0;
    for (const jobs::AnalysisRecord& row : LoggedAnalyses(dir_ / db, id)) {
      EXPECT_TRUE(row.objective_gradients.empty());
      EXPECT_TRUE(row.constraint_gradients.empty());
      if (!row.gradients_unavailable.empty()) {
        ++without;
        EXPECT_THAT(row.gradients_unavailable, HasSubstr(c.reason));
      }
    }
    EXPECT_GT(without, 0) << "the log says why the gradients are missing";
  }
}

TEST_F(ServerTest, SimulatorSensitivityJobResumesBitIdenticallyAfterACrash) {
  const v1::GetJobResponse reference = RunToEnd("reference.db", 7, OscillatorStudyWithSensitivities());
  ASSERT_EQ(reference.summary().state(), v1::JOB_STATE_CONVERGED);
  ASSERT_GT(reference.summary().analyses(), 3);
  const int kResultsBeforeCrash = 3;  // the third is a trial of cycle 2 at the latest
  std::string id;
  {
    auto server = StartServer("crash.db");
    id = Submit(*server, OscillatorStudyWithSensitivities());
    FakeWorker worker(server->InProcessChannel(), 99);
    ASSERT_EQ(worker.Run(kResultsBeforeCrash), kResultsBeforeCrash);
    ASSERT_EQ(Get(*server, id).summary().state(), v1::JOB_STATE_RUNNING);
    // Destroyed without Shutdown: the database says RUNNING, as after a crash.
  }
  auto server = StartServer("crash.db");
  FakeWorker worker(server->InProcessChannel(), 3);
  worker.Run();
  // Replay handed the logged gradients back: no analysis was repeated.
  EXPECT_EQ(worker.tasks_wanting_gradients(), reference.summary().analyses() - kResultsBeforeCrash);
  EXPECT_EQ(worker.tasks_without_gradients(), 0);
  v1::GetJobResponse finished = Get(*server, id);
  EXPECT_EQ(finished.summary().state(), v1::JOB_STATE_CONVERGED);
  ExpectSameCycles(reference, finished);
}

TEST_F(ServerTest, CancelThenResumeGivesTheSameResult) {
  v1::GetJobResponse reference = RunToEnd("reference.db", 7);
  auto server = StartServer("cancel.db");
  const std::string id = Submit(*server, OscillatorStudy());
  {
    FakeWorker worker(server->InProcessChannel(), 10);
    worker.Run(5);  // leaves taken tasks unanswered, as a busy worker would
  }
  FakeWorker worker(server->InProcessChannel(), 11);
  auto stub = v1::JobService::NewStub(server->InProcessChannel());
  v1::JobRef ref;
  ref.set_job_id(id);
  {
    grpc::ClientContext context;
    v1::JobSummary summary;
    ASSERT_TRUE(stub->Cancel(&context, ref, &summary).ok());
    EXPECT_EQ(summary.state(), v1::JOB_STATE_CANCELLED);
  }
  EXPECT_EQ(worker.Run(), 0);  // nothing is offered for a cancelled job
  {
    grpc::ClientContext context;
    v1::JobSummary summary;
    ASSERT_TRUE(stub->Resume(&context, ref, &summary).ok());
    EXPECT_EQ(summary.state(), v1::JOB_STATE_RUNNING);
  }
  worker.Run();
  ExpectSameCycles(reference, Get(*server, id));
  grpc::ClientContext context;
  v1::JobSummary summary;
  grpc::Status status = stub->Resume(&context, ref, &summary);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
}

jobs::manager::JobManagerOptions OneRunningJob(int max_queued_per_user = 0) {
  jobs::manager::JobManagerOptions manager;
  manager.admission.max_running_jobs = 1;
  manager.admission.max_queued_jobs_per_user = max_queued_per_user;
  return manager;
}

// With one job allowed to run, the next ones wait (QUEUED, saying where they
// are in the queue) and start in submission order as the running one ends;
// a job that waited gives the result it gives when it runs at once.
TEST_F(ServerTest, JobsBeyondTheRunningLimitWaitAndStartInSubmissionOrder) {
  v1::GetJobResponse reference = RunToEnd("reference.db", 7);
  auto server = StartServer("queue.db", OneRunningJob());
  const std::string a = Submit(*server, OscillatorStudy());
  const std::string b = Submit(*server, OscillatorStudy());
  const std::string c = Submit(*server, OscillatorStudy());
  EXPECT_EQ(Get(*server, a).summary().state(), v1::JOB_STATE_RUNNING);
  v1::GetJobResponse waiting_b = Get(*server, b);
  EXPECT_EQ(waiting_b.summary().state(), v1::JOB_STATE_QUEUED);
  EXPECT_THAT(waiting_b.summary().message(), HasSubstr("waiting to run: 0 jobs ahead in the queue"));
  EXPECT_THAT(waiting_b.summary().message(), HasSubstr("--max-running-jobs 1"));
  EXPECT_THAT(Get(*server, c).summary().message(), HasSubstr("1 job ahead"));

  // One result at a time: never two jobs running, and each starts (in
  // submission order) only once the one before it has ended.
  FakeWorker worker(server->InProcessChannel(), 7);
  const std::vector<std::string> ids = {a, b, c};
  std::vector<int> started_at(3, -1), ended_at(3, -1);
  for (int step = 0; step < 1000 && ended_at[2] < 0; ++step) {
    int running = 0;
    for (int j = 0; j < 3; ++j) {
      const v1::JobState state = Get(*server, ids[static_cast<size_t>(j)]).summary().state();
      running += state == v1::JOB_STATE_RUNNING ? 1 : 0;
      if (state != v1::JOB_STATE_QUEUED && started_at[static_cast<size_t>(j)] < 0) started_at[static_cast<size_t>(j)] = step;
      if (state == v1::JOB_STATE_CONVERGED && ended_at[static_cast<size_t>(j)] < 0) ended_at[static_cast<size_t>(j)] = step;
    }
    ASSERT_LE(running, 1) << "step " << step;
    worker.Run(1);
  }
  ASSERT_GE(ended_at[2], 0);
  EXPECT_EQ(started_at[0], 0);
  EXPECT_EQ(started_at[1], ended_at[0]);
  EXPECT_EQ(started_at[2], ended_at[1]);
  for (const std::string& id : ids) {
    v1::GetJobResponse done = Get(*server, id);
    EXPECT_EQ(done.summary().state(), v1::JOB_STATE_CONVERGED) << id;
    ExpectSameCycles(reference, done);
  }
}

TEST_F(ServerTest, AUserWithTooManyWaitingJobsIsRefusedSayingTheLimit) {
  auto server = StartServer("quota.db", OneRunningJob(/*max_queued_per_user=*/1));
  Submit(*server, OscillatorStudy());  // runs
  Submit(*server, OscillatorStudy());  // waits
  grpc::Status status = TrySubmit(*server, OscillatorStudy());
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("already has 1 jobs waiting to run (the server's "
                                                "--max-queued-jobs-per-user)"));
}

// A waiting job stays waiting across a stop of the server and starts after
// the job that ran before it; cancelled while waiting, it never starts, and
// `resume` puts it back in the queue.
TEST_F(ServerTest, WaitingJobsKeepTheirPlaceAcrossARestartAndCanBeCancelled) {
  v1::GetJobResponse reference = RunToEnd("reference.db", 7);
  std::string a, b, c;
  {
    auto server = StartServer("restart.db", OneRunningJob());
    a = Submit(*server, OscillatorStudy());
    b = Submit(*server, OscillatorStudy());
    c = Submit(*server, OscillatorStudy());
    FakeWorker worker(server->InProcessChannel(), 5);
    worker.Run(6);
    server->Shutdown();
  }
  auto server = StartServer("restart.db", OneRunningJob());
  EXPECT_EQ(Get(*server, a).summary().state(), v1::JOB_STATE_RUNNING);
  EXPECT_EQ(Get(*server, b).summary().state(), v1::JOB_STATE_QUEUED);
  auto stub = v1::JobService::NewStub(server->InProcessChannel());
  v1::JobRef ref;
  ref.set_job_id(c);
  {
    grpc::ClientContext context;
    v1::JobSummary summary;
    ASSERT_TRUE(stub->Cancel(&context, ref, &summary).ok());
    EXPECT_EQ(summary.state(), v1::JOB_STATE_CANCELLED);
  }
  {
    grpc::ClientContext context;
    v1::JobSummary summary;
    ASSERT_TRUE(stub->Resume(&context, ref, &summary).ok());
    EXPECT_EQ(summary.state(), v1::JOB_STATE_QUEUED);
    EXPECT_THAT(summary.message(), HasSubstr("1 job ahead"));
  }
  FakeWorker worker(server->InProcessChannel(), 6);
  worker.Run();
  for (const std::string& id : {a, b, c}) {
    v1::GetJobResponse done = Get(*server, id);
    EXPECT_EQ(done.summary().state(), v1::JOB_STATE_CONVERGED) << id;
    ExpectSameCycles(reference, done);
  }
}

// A state change and its line in the event log are one commit (one sync
// at the default durability), from the submit to the end.
TEST_F(ServerTest, EachStateChangeIsOneCommitWithItsEvent) {
  auto server = StartServer("a.db");
  const store::Store& log = server->store();
  std::int64_t commits = log.Commits();
  const std::string id = Submit(*server, OscillatorStudy());
  EXPECT_EQ(log.Commits(), commits + 1);
  {
    FakeWorker worker(server->InProcessChannel(), 10);
    worker.Run(5);
  }
  std::unique_ptr<v1::JobService::Stub> stub = v1::JobService::NewStub(server->InProcessChannel());
  v1::JobRef ref;
  ref.set_job_id(id);
  for (const bool cancel : {true, false}) {
    commits = log.Commits();
    grpc::ClientContext context;
    v1::JobSummary summary;
    const grpc::Status status = cancel ? stub->Cancel(&context, ref, &summary) : stub->Resume(&context, ref, &summary);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(log.Commits(), commits + 1) << (cancel ? "cancel" : "resume");
  }
  FakeWorker worker(server->InProcessChannel(), 11);
  worker.Run();
  EXPECT_EQ(Get(*server, id).summary().state(), v1::JOB_STATE_CONVERGED);
  absl::StatusOr<std::vector<store::EventRow>> events = server->store().LoadEvents(id);
  ASSERT_TRUE(events.ok()) << events.status();
  std::vector<std::string> kinds;
  for (const store::EventRow& e : *events) kinds.push_back(e.kind);
  EXPECT_EQ(kinds, (std::vector<std::string>{"submitted", "cancelled", "resumed", "ended"}));
  EXPECT_THAT(events->back().message, HasSubstr("CONVERGED after"));
}

TEST_F(ServerTest, FinishedJobIsServedFromTheLogAfterRestart) {
  std::string id;
  v1::GetJobResponse before;
  {
    auto server = StartServer("a.db");
    id = Submit(*server, OscillatorStudy());
    FakeWorker worker(server->InProcessChannel(), 1);
    worker.Run();
    before = Get(*server, id);
    server->Shutdown();
  }
  auto server = StartServer("a.db");
  v1::GetJobResponse after = Get(*server, id);
  EXPECT_EQ(after.summary().state(), v1::JOB_STATE_CONVERGED);
  EXPECT_EQ(after.summary().cycles(), before.summary().cycles());
  EXPECT_EQ(after.summary().analyses(), before.summary().analyses());
  EXPECT_EQ(after.summary().objective(), before.summary().objective());
  EXPECT_EQ(after.summary().max_violation(), before.summary().max_violation());
  ExpectSameCycles(before, after);
  // Nothing is rescheduled for an ended job.
  FakeWorker worker(server->InProcessChannel(), 2);
  EXPECT_TRUE(worker.Acquire(100).empty());
}

TEST_F(ServerTest, FinishedJobsKeepOnlyTheirSummaryInMemory) {
  auto server = StartServer("a.db");
  const std::string first = Submit(*server, OscillatorStudy("first"));
  {
    FakeWorker worker(server->InProcessChannel(), 1);
    worker.Run();
  }
  const std::string second = Submit(*server, OscillatorStudy("second"));
  EXPECT_EQ(server->manager().ResidentJobs(), 1u) << "only the running job";
  const v1::GetJobResponse view = Get(*server, first);  // read back from the database
  EXPECT_EQ(view.summary().state(), v1::JOB_STATE_CONVERGED);
  EXPECT_GT(view.cycles_size(), 0);
  EXPECT_TRUE(view.has_study()) << "the study bytes come back from the database";
  EXPECT_EQ(server->manager().ResidentJobs(), 1u) << "a view does not keep the finished job in memory";
  {
    FakeWorker worker(server->InProcessChannel(), 2);
    worker.Run();
  }
  EXPECT_EQ(server->manager().ResidentJobs(), 0u);
  // The summary kept in memory is the one the full view gives.
  auto stub = v1::JobService::NewStub(server->InProcessChannel());
  grpc::ClientContext context;
  v1::ListJobsResponse jobs;
  ASSERT_TRUE(stub->List(&context, v1::ListJobsRequest(), &jobs).ok());
  ASSERT_EQ(jobs.jobs_size(), 2);
  EXPECT_EQ(jobs.jobs(0).SerializeAsString(), view.summary().SerializeAsString());
}

TEST_F(ServerTest, JobsAreListedInSubmissionOrder) {
  auto server = StartServer("a.db");
  std::vector<std::string> ids;
  for (int i = 0; i < 11; ++i) ids.push_back(Submit(*server, OscillatorStudy("s" + std::to_string(i))));
  auto stub = v1::JobService::NewStub(server->InProcessChannel());
  grpc::ClientContext context;
  v1::ListJobsResponse jobs;
  ASSERT_TRUE(stub->List(&context, v1::ListJobsRequest(), &jobs).ok());
  ASSERT_EQ(jobs.jobs_size(), 11);
  for (int i = 0; i < 11; ++i) {
    EXPECT_EQ(jobs.jobs(i).job_id(), ids[static_cast<size_t>(i)]);
    EXPECT_EQ(jobs.jobs(i).state(), v1::JOB_STATE_RUNNING);
  }
}

TEST_F(ServerTest, WorkerForgottenByARestartIsAskedToRegisterAgain) {
  std::string worker_id;
  {
    auto server = StartServer("a.db");
    FakeWorker worker(server->InProcessChannel(), 1);
    worker_id = worker.worker_id();
  }
  auto server = StartServer("a.db");
  auto stub = v1::WorkerService::NewStub(server->InProcessChannel());
  {
    grpc::ClientContext context;
    v1::HeartbeatRequest request;
    request.set_worker_id(worker_id);
    v1::HeartbeatResponse response;
    ASSERT_TRUE(stub->Heartbeat(&context, request, &response).ok());
    EXPECT_FALSE(response.known());
  }
  grpc::ClientContext context;
  v1::AcquireTasksRequest request;
  request.set_worker_id(worker_id);
  v1::AcquireTasksResponse response;
  EXPECT_EQ(stub->AcquireTasks(&context, request, &response).error_code(), grpc::StatusCode::NOT_FOUND);
}

// The oscillator study as an external scene naming driver "oscillator-sim".
v1::Study ExternalOscillatorStudy() {
  v1::Study study = OscillatorStudy("external oscillator");
  v1::Scene* scene = study.mutable_scene();
  scene->clear_lumped();
  v1::ExternalModel* model = scene->mutable_external();
  model->set_driver("oscillator-sim");
  for (const char* parameter : {"k", "c"}) {
    v1::ExternalInput* input = model->add_inputs();
    input->set_name(parameter);
    input->mutable_value()->set_param(parameter);
  }
  for (v1::Output& output : *scene->mutable_outputs()) {
    const std::string name = output.name();
    output.Clear();
    output.set_name(name);
    output.mutable_external_series()->set_name(name);
  }
  return study;
}

// A study naming a driver no registered worker declares is refused at
// submit with the drivers that exist; once its workers are gone (here, a
// restart forgets every worker) the job says what it waits for.
TEST_F(ServerTest, ADriverNoWorkerDeclaresIsRefusedAtSubmitAndNamedWhileTheJobWaits) {
  std::string id;
  {
    auto server = StartServer("drivers.db");
    auto jobs = v1::JobService::NewStub(server->InProcessChannel());
    v1::SubmitJobRequest request;
    request.set_study(ExternalOscillatorStudy().SerializeAsString());
    request.set_source_name("external.study.textproto");
    {
      grpc::ClientContext context;
      v1::SubmitJobResponse response;
      grpc::Status status = jobs->Submit(&context, request, &response);
      EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
      EXPECT_NE(status.error_message().find("external.study.textproto: scene.external.driver: no registered worker "
                                            "declares driver \"oscillator-sim\"; the registered workers declare "
                                            "no drivers"),
                std::string::npos)
          << status.error_message();
    }
    auto workers = v1::WorkerService::NewStub(server->InProcessChannel());
    {
      grpc::ClientContext context;
      v1::RegisterWorkerRequest registration;
      registration.set_name("sim");
      registration.set_slots(1);
      registration.add_drivers("oscillator-sim");
      v1::RegisterWorkerResponse registered;
      ASSERT_TRUE(workers->Register(&context, registration, &registered).ok());
    }
    grpc::ClientContext context;
    v1::SubmitJobResponse response;
    grpc::Status status = jobs->Submit(&context, request, &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    id = response.job_id();
    EXPECT_EQ(Get(*server, id).summary().waiting_for(), "");
    server->Shutdown();
  }
  auto server = StartServer("drivers.db");
  const v1::GetJobResponse resumed = Get(*server, id);
  EXPECT_EQ(resumed.summary().state(), v1::JOB_STATE_RUNNING);
  EXPECT_NE(resumed.summary().waiting_for().find("no registered worker declares driver \"oscillator-sim\""),
            std::string::npos)
      << resumed.summary().waiting_for();
}

TEST(ListenAddress, OnlyLoopbackAndLocalSocketsAreLoopback) {
  for (const char* local : {"127.0.0.1:50051", "127.1.2.3:0", "localhost:50051", "[::1]:50051", "unix:/tmp/mbopt.sock"}) {
    EXPECT_TRUE(IsLoopbackAddress(local)) << local;
  }
  for (const char* remote : {"0.0.0.0:50051", ":50051", "[::]:50051", "10.0.0.5:50051", "[fe80::1]:50051",
                             "server.example.org:50051", "128.0.0.1:50051", "[::1:50051"}) {
    EXPECT_FALSE(IsLoopbackAddress(remote)) << remote;
  }
}

TEST(ListenAddress, ClientsDialTheHostWithTheChosenPortOrTheSocketAsGiven) {
  EXPECT_EQ(DialAddress("127.0.0.1:0", 40123), "127.0.0.1:40123");
  EXPECT_EQ(DialAddress("[::1]:0", 40123), "[::1]:40123");
  EXPECT_EQ(DialAddress("localhost:50051", 50051), "localhost:50051");
  EXPECT_EQ(DialAddress("unix:/tmp/mbopt.sock", 1), "unix:/tmp/mbopt.sock");
  EXPECT_EQ(DialAddress("unix-abstract:mbopt", 1), "unix-abstract:mbopt");
}

// A server on a Unix domain socket says where it is (it said "unix:1"),
// and a client reaches it there.
TEST_F(ServerTest, ServerOnAUnixSocketGivesTheSocketAsItsAddress) {
  ServerOptions options;
  options.listen_address = "unix:" + (dir_ / "server.sock").string();
  options.db_path = (dir_ / "a.db").string();
  absl::StatusOr<std::unique_ptr<MboptServer>> server = MboptServer::Start(options);
  ASSERT_TRUE(server.ok()) << server.status();
  EXPECT_EQ((*server)->address(), options.listen_address);
  std::unique_ptr<v1::JobService::Stub> stub =
      v1::JobService::NewStub(grpc::CreateChannel((*server)->address(), grpc::InsecureChannelCredentials()));
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  v1::ListJobsResponse response;
  EXPECT_TRUE(stub->List(&context, v1::ListJobsRequest(), &response).ok());
}

TEST_F(ServerTest, AddressOffLoopbackIsRefusedWithoutInsecureBeforeAnythingOpens) {
  for (const char* address : {"0.0.0.0:0", "[::]:0", ":0"}) {
    ServerOptions options;
    options.listen_address = address;
    options.db_path = (dir_ / "never.db").string();
    absl::StatusOr<std::unique_ptr<MboptServer>> server = MboptServer::Start(options);
    ASSERT_FALSE(server.ok()) << address;
    EXPECT_EQ(server.status().code(), absl::StatusCode::kFailedPrecondition);
    EXPECT_THAT(server.status().message(), HasSubstr("--insecure"));
    EXPECT_FALSE(std::filesystem::exists(dir_ / "never.db"));
  }
}

TEST_F(ServerTest, SubmitWithoutStudyIsInvalidArgument) {
  auto server = StartServer("a.db");
  auto stub = v1::JobService::NewStub(server->InProcessChannel());
  grpc::ClientContext context;
  v1::SubmitJobResponse response;
  grpc::Status status = stub->Submit(&context, v1::SubmitJobRequest(), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("study"));
}

TEST_F(ServerTest, OversizedStudyOrSourceNameIsRefusedNamingTheLimit) {
  auto server = StartServer("a.db");
  auto stub = v1::JobService::NewStub(server->InProcessChannel());
  // Submits the oscillator study changed by `edit`; expects a refusal naming `limit`.
  auto expect_refused = [&](const std::function<void(v1::Study&, v1::SubmitJobRequest&)>& edit,
                            const std::string& limit) {
    v1::SubmitJobRequest request;
    v1::Study study = OscillatorStudy();
    edit(study, request);
    request.set_study(study.SerializeAsString());
    grpc::ClientContext context;
    v1::SubmitJobResponse response;
    grpc::Status status = stub->Submit(&context, request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << limit;
    EXPECT_THAT(status.error_message(), HasSubstr(limit));
  };
  // One MiB over what Submit takes (two input files and a carried FMU).
  constexpr std::size_t kOver = JobServiceImpl::kMaxStudyMessageBytes + (std::size_t{1} << 20);
  expect_refused([](v1::Study& s, v1::SubmitJobRequest&) { s.set_description(std::string(kOver, 'x')); },
                 absl::StrCat("more than the limit of ", JobServiceImpl::kMaxStudyMessageBytes >> 20, " MB"));
  // Under that limit, a field over its own bound is refused by the study's reader, naming the field.
  expect_refused([](v1::Study& s, v1::SubmitJobRequest&) { s.set_description(std::string(33 << 20, 'x')); },
                 "description: text of 34603008 bytes, more than the limit of 65536");
  expect_refused([](v1::Study&, v1::SubmitJobRequest& r) { r.set_source_name(std::string(5000, 'p')); },
                 "source_name has 5000 bytes");
  // A 100 KB study whose constraint name has 100,000 characters: each of its
  // rows carried a copy, and the server grew to 2.4 GB.
  expect_refused(
      [](v1::Study& s, v1::SubmitJobRequest&) {
        ASSERT_GT(s.constraints_size(), 0);
        s.mutable_constraints(0)->set_name(std::string(100'000, 'c'));
      },
      "constraints[0].name: a name of 100000 bytes, more than the limit of 256");
  grpc::ClientContext context;
  v1::ListJobsResponse jobs;
  ASSERT_TRUE(stub->List(&context, v1::ListJobsRequest(), &jobs).ok());
  EXPECT_EQ(jobs.jobs_size(), 0) << "nothing was stored";
}

TEST_F(ServerTest, BadStudyIsInvalidArgumentNamingTheField) {
  auto server = StartServer("a.db");
  v1::Study study = OscillatorStudy();
  study.mutable_variables(1)->set_parameter("no_such_parameter");
  grpc::Status status = TrySubmitFrom(*server, study, "bad.study.textproto");
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("bad.study.textproto"));
  EXPECT_THAT(status.error_message(), HasSubstr("no_such_parameter"));
  auto stub = v1::JobService::NewStub(server->InProcessChannel());
  grpc::ClientContext list_context;
  v1::ListJobsResponse jobs;
  ASSERT_TRUE(stub->List(&list_context, v1::ListJobsRequest(), &jobs).ok());
  EXPECT_EQ(jobs.jobs_size(), 0);
}

TEST_F(ServerTest, AStudySentWithoutASourceNameIsTheSubmittedStudyInMessages) {
  auto server = StartServer("a.db");
  v1::Study study = OscillatorStudy();
  study.mutable_variables(1)->set_parameter("no_such_parameter");
  grpc::Status status = TrySubmitFrom(*server, study, "");
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("the submitted study"));
  EXPECT_THAT(status.error_message(), HasSubstr("no_such_parameter"));
}

TEST_F(ServerTest, UnknownJobIsNotFoundNamingTheId) {
  auto server = StartServer("a.db");
  auto stub = v1::JobService::NewStub(server->InProcessChannel());
  v1::JobRef ref;
  ref.set_job_id("job-404");
  {
    grpc::ClientContext context;
    v1::GetJobResponse response;
    grpc::Status status = stub->Get(&context, ref, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
    EXPECT_THAT(status.error_message(), HasSubstr("job-404"));
  }
  {
    grpc::ClientContext context;
    v1::JobSummary response;
    EXPECT_EQ(stub->Cancel(&context, ref, &response).error_code(), grpc::StatusCode::NOT_FOUND);
  }
  {
    grpc::ClientContext context;
    auto reader = stub->Watch(&context, ref);
    v1::JobEvent event;
    EXPECT_FALSE(reader->Read(&event));
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::NOT_FOUND);
  }
}

// A result in pieces is refused on its first piece when it says it is over
// the server's result limit (nothing is held), and when its pieces do not add
// up to what it said or do not make a result; the job goes on.
TEST_F(ServerTest, ResultInPiecesOverTheLimitOrNotAddingUpIsRefused) {
  ServerOptions options;
  options.listen_address = "127.0.0.1:0";
  options.db_path = (dir_ / "a.db").string();
  options.lease_ms = kLeaseMs;
  options.heartbeat_ms = kLeaseMs / 4;
  options.clock = &clock_;
  options.max_result_bytes = 1000;
  absl::StatusOr<std::unique_ptr<MboptServer>> server = MboptServer::Start(options);
  ASSERT_TRUE(server.ok()) << server.status();
  Submit(**server, OscillatorStudy());
  FakeWorker worker((*server)->InProcessChannel(), 5);
  auto send = [&](std::int64_t total, const std::vector<std::string>& pieces) {
    grpc::ClientContext context;
    v1::ReportResultsResponse response;
    std::unique_ptr<grpc::ClientWriter<v1::ResultPiece>> writer =
        worker.stub().ReportResultInPieces(&context, &response);
    for (size_t i = 0; i < pieces.size(); ++i) {
      v1::ResultPiece piece;
      if (i == 0) {
        piece.set_worker_id(worker.worker_id());
        piece.set_total_bytes(total);
      }
      piece.set_data(pieces[i]);
      if (!writer->Write(piece)) break;
    }
    writer->WritesDone();
    return writer->Finish();
  };
  grpc::Status over = send(2000, {std::string(500, 'a'), std::string(500, 'b')});
  EXPECT_EQ(over.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(over.error_message(), HasSubstr("--max-result-mb"));
  grpc::Status more = send(10, {std::string(8, 'a'), std::string(8, 'b')});
  EXPECT_EQ(more.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(more.error_message(), HasSubstr("more than its 10 bytes"));
  grpc::Status fewer = send(10, {std::string(5, 'a')});
  EXPECT_EQ(fewer.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(fewer.error_message(), HasSubstr("5 of its 10 bytes"));
  grpc::Status garbage = send(4, {std::string("\xff\xff"), std::string("\xff\xff")});
  EXPECT_EQ(garbage.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(garbage.error_message(), HasSubstr("do not make a TaskResult"));
  // The job is untouched: the worker still runs it to its end.
  EXPECT_GT(worker.Run(), 0);
}

TEST_F(ServerTest, GarbageResultIsRejectedWhileAnotherJobContinues) {
  auto server = StartServer("a.db");
  const std::string first = Submit(*server, OscillatorStudy("first"));
  const std::string second = Submit(*server, OscillatorStudy("second"));
  FakeWorker worker(server->InProcessChannel(), 11);
  std::vector<v1::AnalysisTask> tasks = worker.Acquire(1);
  ASSERT_EQ(tasks.size(), 1u);
  // Wrong vector sizes.
  v1::TaskResult garbage;
  garbage.set_worker_id(worker.worker_id());
  garbage.set_task_id(tasks[0].task_id());
  garbage.set_job_id(tasks[0].job_id());
  garbage.set_request_id(tasks[0].request_id());
  garbage.set_ok(true);
  garbage.add_objective_terms(1.0);
  for (int i = 0; i < 5; ++i) garbage.add_constraint_values(1.0);
  {
    grpc::ClientContext context;
    v1::ReportResultResponse response;
    grpc::Status status = worker.stub().ReportResult(&context, garbage, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("constraint values"));
  }
  // An unknown task of a known job, and a task of an unknown job.
  {
    v1::TaskResult unknown = garbage;
    unknown.set_task_id(tasks[0].job_id() + "/999/1");
    unknown.set_request_id(999);
    unknown.clear_constraint_values();
    unknown.add_constraint_values(1.0);
    grpc::ClientContext context;
    v1::ReportResultResponse response;
    grpc::Status status = worker.stub().ReportResult(&context, unknown, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    EXPECT_FALSE(response.accepted());
  }
  {
    v1::TaskResult unknown = garbage;
    unknown.set_job_id("job-77");
    grpc::ClientContext context;
    v1::ReportResultResponse response;
    EXPECT_EQ(worker.stub().ReportResult(&context, unknown, &response).error_code(), grpc::StatusCode::NOT_FOUND);
  }
  // The rejected attempt is retried and both jobs run to the same end as
  // a clean run.
  worker.Run();
  v1::GetJobResponse reference = RunToEnd("reference.db", 7);
  for (const std::string& id : {first, second}) {
    v1::GetJobResponse job = Get(*server, id);
    EXPECT_EQ(job.summary().state(), v1::JOB_STATE_CONVERGED) << id;
    ExpectSameCycles(reference, job);
  }
}

// Reports `task` as a failed analysis of `kind`; true when the server took it.
bool ReportFailure(FakeWorker& worker, const std::string& job_id, const v1::AnalysisTask& task,
                   v1::AnalysisFailureKind kind, const std::string& reason) {
  v1::TaskResult failure;
  failure.set_worker_id(worker.worker_id());
  failure.set_task_id(task.task_id());
  failure.set_job_id(job_id);
  failure.set_request_id(task.request_id());
  failure.set_ok(false);
  failure.set_failure_reason(reason);
  failure.set_failure_kind(kind);
  grpc::ClientContext context;
  v1::ReportResultResponse response;
  const grpc::Status status = worker.stub().ReportResult(&context, failure, &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return status.ok() && response.accepted();
}

TEST_F(ServerTest, FailedAnalysisGoesToTheOptimizerWithoutRetry) {
  auto server = StartServer("a.db");
  const std::string id = Submit(*server, OscillatorStudy());
  FakeWorker worker(server->InProcessChannel(), 12);
  // The first cycle: x0 (request 0) and its perturbations.
  std::vector<v1::AnalysisTask> tasks = worker.Acquire(100);
  ASSERT_FALSE(tasks.empty());
  for (const v1::AnalysisTask& task : tasks) {
    if (task.request_id() != 0) {
      ASSERT_TRUE(worker.Answer(task).ok());
      continue;
    }
    EXPECT_TRUE(ReportFailure(worker, id, task, v1::ANALYSIS_FAILURE_INTEGRATOR, "integrator failed at t = 0.3 s"));
  }
  // Not retried: nothing more is offered.
  EXPECT_TRUE(worker.Acquire(100).empty());
  v1::GetJobResponse job = Get(*server, id);
  // The initial design cannot be analysed: the run fails, with the reason.
  EXPECT_EQ(job.summary().state(), v1::JOB_STATE_FAILED);
  EXPECT_THAT(job.summary().message(), HasSubstr("integrator failed"));
  // The failure's kind reaches the job's summary and its message.
  EXPECT_THAT(job.summary().message(), HasSubstr("(integrator)"));
  ASSERT_EQ(job.summary().failed_analyses_by_kind().count("integrator"), 1u);
  EXPECT_EQ(job.summary().failed_analyses_by_kind().at("integrator"), 1);
}

// A job's running time is read from the server's injected clock.
TEST_F(ServerTest, JobWallTimeFollowsTheInjectedClock) {
  auto server = StartServer("clock.db");
  const std::string id = Submit(*server, OscillatorStudy());
  const double before = Get(*server, id).summary().wall_seconds();
  clock_.Advance(1500);
  EXPECT_DOUBLE_EQ(Get(*server, id).summary().wall_seconds() - before, 1.5);
}

// A resumed job counts the failures of its replayed analyses too.
TEST_F(ServerTest, FailureKindsSurviveAResume) {
  std::string id;
  {
    auto server = StartServer("kinds.db");
    id = Submit(*server, OscillatorStudy());
    FakeWorker worker(server->InProcessChannel(), 12);
    std::vector<v1::AnalysisTask> tasks = worker.Acquire(100);
    ASSERT_GT(tasks.size(), 1u);
    // A perturbation fails as an assembly failure; it is retried on the other
    // side, so the job goes on.
    for (const v1::AnalysisTask& task : tasks) {
      if (task.request_id() == 0) continue;
      EXPECT_TRUE(ReportFailure(worker, id, task, v1::ANALYSIS_FAILURE_ASSEMBLY, "joint B cannot close at t = 0 s"));
      break;
    }
    EXPECT_EQ(Get(*server, id).summary().failed_analyses_by_kind().at("assembly"), 1);
  }
  // The server is gone; a new one replays the log.
  auto server = StartServer("kinds.db");
  v1::GetJobResponse job = Get(*server, id);
  ASSERT_EQ(job.summary().failed_analyses_by_kind().count("assembly"), 1u);
  EXPECT_EQ(job.summary().failed_analyses_by_kind().at("assembly"), 1);
}

std::set<std::int64_t> RequestIds(const std::vector<v1::AnalysisTask>& tasks) {
  std::set<std::int64_t> ids;
  for (const v1::AnalysisTask& t : tasks) ids.insert(t.request_id());
  return ids;
}

// Every task the worker can get, one per call: a call for many would give
// it only its share of them (the other fake workers count as idle).
std::vector<v1::AnalysisTask> AcquireOneByOne(FakeWorker& worker) {
  std::vector<v1::AnalysisTask> all;
  while (true) {
    std::vector<v1::AnalysisTask> one = worker.Acquire(1);
    if (one.empty()) return all;
    all.insert(all.end(), one.begin(), one.end());
  }
}

// A holder of the (shared) worker token registers a worker of its own and
// answers the tasks leased to an honest worker with values of its choosing,
// under its own id or under the honest worker's public id. Every such result
// is refused and logged; the job ends as a clean run does, bit for bit, and
// its log names only the honest worker.
TEST_F(ServerTest, AResultFromAWorkerThatHoldsNoLeaseOfItsTaskIsRefusedAndLogged) {
  const v1::GetJobResponse clean = RunToEnd("clean.db", 1);
  auto server = StartServer("a.db");
  const std::string id = Submit(*server, OscillatorStudy());
  FakeWorker honest(server->InProcessChannel(), 1, "honest");
  FakeWorker thief(server->InProcessChannel(), 2, "thief");
  EXPECT_NE(honest.worker_id(), scheduler::PublicWorkerId(honest.worker_id())) << "ids have a secret part";
  std::vector<v1::AnalysisTask> leased = honest.Acquire(64);
  ASSERT_FALSE(leased.empty());

  ::testing::internal::CaptureStderr();
  int refused = 0;
  for (const std::string& claimed : {thief.worker_id(), scheduler::PublicWorkerId(honest.worker_id())}) {
    for (const v1::AnalysisTask& task : leased) {
      v1::TaskResult forged = thief.ResultOf(task);
      forged.set_worker_id(claimed);
      for (double& value : *forged.mutable_objective_terms()) value = 1.0;
      grpc::ClientContext context;
      v1::ReportResultResponse response;
      const grpc::Status status = thief.stub().ReportResult(&context, forged, &response);
      EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED) << claimed;
      EXPECT_THAT(status.error_message(), HasSubstr("was never leased to worker"));
      refused += status.error_code() == grpc::StatusCode::PERMISSION_DENIED;
    }
  }
  // In a batch, as workers usually report: each result refused in its answer.
  v1::ReportResultsResponse batch;
  ASSERT_TRUE(thief.AnswerTogether(leased, &batch).ok());
  ASSERT_EQ(batch.answers_size(), static_cast<int>(leased.size()));
  for (const v1::ResultAnswer& answer : batch.answers()) {
    EXPECT_FALSE(answer.accepted());
    EXPECT_THAT(answer.error(), HasSubstr("was never leased to worker"));
  }
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(refused, 2 * static_cast<int>(leased.size()));
  EXPECT_THAT(log, HasSubstr("audit: refused ReportResult from peer"));
  EXPECT_THAT(log, HasSubstr("audit: refused ReportResults from peer"));
  EXPECT_THAT(log, ::testing::Not(HasSubstr(honest.worker_id()))) << "the secret part of an id is never logged";

  // The honest worker's answers are taken, and the job ends as the clean run.
  for (const v1::AnalysisTask& task : leased) {
    bool accepted = false;
    ASSERT_TRUE(honest.Answer(task, &accepted).ok());
    EXPECT_TRUE(accepted);
  }
  honest.Run();
  const v1::GetJobResponse job = Get(*server, id);
  EXPECT_EQ(job.summary().state(), v1::JOB_STATE_CONVERGED) << job.summary().message();
  ExpectSameCycles(job, clean);
  absl::StatusOr<std::vector<jobs::AnalysisRecord>> analyses = server->store().LoadAnalyses(id);
  ASSERT_TRUE(analyses.ok()) << analyses.status();
  ASSERT_FALSE(analyses->empty());
  for (const jobs::AnalysisRecord& a : *analyses) {
    EXPECT_EQ(a.worker, scheduler::PublicWorkerId(honest.worker_id())) << "request " << a.request_id;
  }
}

TEST_F(ServerTest, LostWorkersTasksAreRetriedElsewhereThenGivenUpAfterThreeAttempts) {
  auto server = StartServer("a.db");
  const std::string id = Submit(*server, OscillatorStudy());
  FakeWorker a(server->InProcessChannel(), 1, "a");
  FakeWorker b(server->InProcessChannel(), 2, "b");
  FakeWorker c(server->InProcessChannel(), 3, "c");
  std::vector<v1::AnalysisTask> first = AcquireOneByOne(a);
  ASSERT_FALSE(first.empty());
  clock_.Advance(kLeaseMs);
  server->manager().ExpireLeases();
  EXPECT_TRUE(AcquireOneByOne(a).empty());  // b and c, who have not failed them, are preferred
  std::vector<v1::AnalysisTask> second = AcquireOneByOne(b);
  EXPECT_EQ(RequestIds(second), RequestIds(first));
  clock_.Advance(kLeaseMs);
  server->manager().ExpireLeases();
  std::vector<v1::AnalysisTask> third = AcquireOneByOne(c);
  EXPECT_EQ(RequestIds(third), RequestIds(first));
  EXPECT_EQ(Get(*server, id).summary().state(), v1::JOB_STATE_RUNNING);
  clock_.Advance(kLeaseMs);
  server->manager().ExpireLeases();
  // Three attempts lost: the analyses are reported failed; x0 of the first
  // cycle is among them, so the run fails.
  v1::GetJobResponse job = Get(*server, id);
  EXPECT_EQ(job.summary().state(), v1::JOB_STATE_FAILED);
  EXPECT_THAT(job.summary().message(), HasSubstr("3 failed attempts"));
  // A late answer of a given-up task is dropped.
  bool accepted = true;
  EXPECT_TRUE(a.Answer(first[0], &accepted).ok());
  EXPECT_FALSE(accepted);
}

TEST_F(ServerTest, ResultsOfSeveralJobsInOneCallAreCommittedInOneTransaction) {
  auto server = StartServer("a.db");
  const std::string first = Submit(*server, OscillatorStudy("first"));
  const std::string second = Submit(*server, OscillatorStudy("second"));
  FakeWorker worker(server->InProcessChannel(), 3);
  // The first cycle of both jobs: the initial designs and their perturbations.
  std::vector<v1::AnalysisTask> tasks = worker.Acquire(64);
  std::set<std::string> jobs;
  for (const v1::AnalysisTask& task : tasks) jobs.insert(task.job_id());
  ASSERT_EQ(jobs, (std::set<std::string>{first, second}));
  const std::int64_t before = server->store().AnalysisTransactions();
  v1::ReportResultsResponse response;
  ASSERT_TRUE(worker.AnswerTogether(tasks, &response).ok());
  EXPECT_EQ(server->store().AnalysisTransactions(), before + 1);
  ASSERT_EQ(response.answers_size(), static_cast<int>(tasks.size()));
  for (const v1::ResultAnswer& answer : response.answers()) {
    EXPECT_TRUE(answer.accepted());
    EXPECT_EQ(answer.error(), "");
  }
  // Both jobs took their results: each has its first cycle's trial on offer.
  for (const std::string& id : {first, second}) {
    EXPECT_EQ(Get(*server, id).summary().analyses(), static_cast<int>(tasks.size() / 2)) << id;
  }
  worker.Run();
  EXPECT_EQ(Get(*server, first).summary().state(), v1::JOB_STATE_CONVERGED);
  EXPECT_EQ(Get(*server, second).summary().state(), v1::JOB_STATE_CONVERGED);
}

TEST_F(ServerTest, CycleRecordsArePublishedOnlyOnceTheLogIsSynced) {
  const v1::GetJobResponse reference = RunToEnd("reference.db", 5);
  std::mutex mutex;
  std::condition_variable changed;
  bool release = false;
  int syncs_asked = 0;
  jobs::manager::JobManagerOptions manager;
  manager.before_log_sync = [&] {
    std::unique_lock<std::mutex> lock(mutex);
    ++syncs_asked;
    changed.notify_all();
    changed.wait(lock, [&] { return release; });
  };
  auto server = StartServer("a.db", manager);
  auto release_sync = [&] {
    std::lock_guard<std::mutex> lock(mutex);
    release = true;
    changed.notify_all();
  };
  absl::Cleanup release_before_the_server_stops = release_sync;  // should an assertion end the test early
  const std::string id = Submit(*server, OscillatorStudy());
  FakeWorker worker(server->InProcessChannel(), 5);
  // Answer until a cycle record waits for the sync (the syncing thread is
  // then held in the hook).
  while (true) {
    ASSERT_EQ(worker.Run(1), 1);
    std::lock_guard<std::mutex> lock(mutex);
    if (syncs_asked > 0) break;
  }
  EXPECT_EQ(Get(*server, id).cycles_size(), 0) << "a record is shown before the log is synced";
  EXPECT_EQ(server->store().LogSyncs(), 0);
  // The job goes on meanwhile: results are taken and the next tasks handed
  // out without waiting for the sync.
  EXPECT_EQ(worker.Run(3), 3);
  release_sync();
  server->manager().WaitForLogSync();
  EXPECT_GE(server->store().LogSyncs(), 1);
  EXPECT_GE(Get(*server, id).cycles_size(), 1);
  worker.Run();
  ExpectSameCycles(reference, Get(*server, id));
}

TEST_F(ServerTest, WatchReplaysPastRecordsThenStreamsUntilTheJobEnds) {
  auto server = StartServer("a.db");
  const std::string id = Submit(*server, OscillatorStudy());
  FakeWorker worker(server->InProcessChannel(), 13);
  worker.Run(6);
  server->manager().WaitForLogSync();  // the records so far are all published
  const int records_before = Get(*server, id).cycles_size();
  auto stub = v1::JobService::NewStub(server->InProcessChannel());
  grpc::ClientContext context;
  v1::JobRef ref;
  ref.set_job_id(id);
  auto reader = stub->Watch(&context, ref);
  // The replay: the records so far, then a summary.
  v1::JobEvent event;
  for (int i = 0; i < records_before; ++i) {
    ASSERT_TRUE(reader->Read(&event));
    ASSERT_TRUE(event.has_cycle());
  }
  ASSERT_TRUE(reader->Read(&event));
  ASSERT_TRUE(event.has_summary());
  // The rest of the run, answered on another thread while this one reads.
  std::thread answering([&] { worker.Run(); });
  int streamed = 0;
  v1::JobSummary last;
  while (reader->Read(&event)) {
    if (event.has_cycle()) ++streamed;
    if (event.has_summary()) last = event.summary();
  }
  answering.join();
  EXPECT_TRUE(reader->Finish().ok());
  EXPECT_EQ(last.state(), v1::JOB_STATE_CONVERGED);
  EXPECT_EQ(records_before + streamed, Get(*server, id).cycles_size());
}

TEST_F(ServerTest, WatchSendsNoProgressAloneWhileTheServerClockStandsAndEndsFromMemory) {
  auto server = StartServer("a.db");
  const std::string id = Submit(*server, OscillatorStudy());
  std::unique_ptr<v1::JobService::Stub> stub = v1::JobService::NewStub(server->InProcessChannel());
  grpc::ClientContext context;
  v1::JobRef ref;
  ref.set_job_id(id);
  std::unique_ptr<grpc::ClientReader<v1::JobEvent>> reader = stub->Watch(&context, ref);
  v1::JobEvent event;
  ASSERT_TRUE(reader->Read(&event));  // the first summary, before any result
  ASSERT_TRUE(event.has_summary());
  // Every result changes the job; most bring no cycle record. The fake
  // clock stands still for the whole run, so no interval ever ends: each
  // summary goes out with records, or is the final one.
  FakeWorker worker(server->InProcessChannel(), 13);
  std::thread answering([&] { worker.Run(); });
  int records = 0;
  int summaries_alone = 0;  // summaries that follow a summary: progress only
  bool after_summary = true;
  v1::JobSummary last;
  while (reader->Read(&event)) {
    if (event.has_cycle()) {
      ++records;
      after_summary = false;
    } else if (event.has_summary()) {
      if (after_summary) ++summaries_alone;
      after_summary = true;
      last = event.summary();
    }
  }
  answering.join();
  EXPECT_TRUE(reader->Finish().ok());
  EXPECT_EQ(last.state(), v1::JOB_STATE_CONVERGED);
  const v1::GetJobResponse job = Get(*server, id);
  EXPECT_EQ(records, job.cycles_size());
  // The job changed with every result (far more often than it made
  // records), and at most the final summary came alone.
  EXPECT_GT(job.summary().analyses(), 2 * job.cycles_size());
  EXPECT_LE(summaries_alone, 1) << job.summary().analyses() << " analyses, " << records << " records";
  // The watcher's last views came from memory: the job gave up its study
  // and records once, when the stream ended, and the Get above read them back.
  EXPECT_EQ(server->manager().Evictions(), 2);
}

// The study's serialized bytes with its fields in reverse order: the same
// study to any parser, but not the bytes protobuf writes (it writes fields
// in number order), so bytes that were parsed and written again differ.
std::string InReverseFieldOrder(const v1::Study& study) {
  std::vector<const google::protobuf::FieldDescriptor*> fields;
  study.GetReflection()->ListFields(study, &fields);
  std::string out;
  for (auto it = fields.rbegin(); it != fields.rend(); ++it) {
    v1::Study only = study;
    for (const google::protobuf::FieldDescriptor* other : fields) {
      if (other != *it) only.GetReflection()->ClearField(&only, other);
    }
    out += only.SerializeAsString();
  }
  return out;
}

// GetStudy's response as it came over the wire, unparsed.
std::string RawGetStudyResponse(MboptServer& server, const std::string& job_id) {
  grpc::GenericStub generic(server.InProcessChannel());
  grpc::CompletionQueue queue;
  grpc::ClientContext context;
  v1::GetStudyRequest request;
  request.set_job_id(job_id);
  grpc::Slice request_slice(request.SerializeAsString());
  grpc::ByteBuffer request_buffer(&request_slice, 1);
  std::unique_ptr<grpc::GenericClientAsyncResponseReader> call =
      generic.PrepareUnaryCall(&context, "/mbopt.v1.WorkerService/GetStudy", request_buffer, &queue);
  call->StartCall();
  grpc::ByteBuffer reply;
  grpc::Status status;
  call->Finish(&reply, &status, reinterpret_cast<void*>(1));
  void* tag = nullptr;
  bool ok = false;
  EXPECT_TRUE(queue.Next(&tag, &ok) && ok);
  EXPECT_TRUE(status.ok()) << status.error_message();
  std::vector<grpc::Slice> slices;
  EXPECT_TRUE(reply.Dump(&slices).ok());
  std::string raw;
  for (const grpc::Slice& slice : slices) raw.append(reinterpret_cast<const char*>(slice.begin()), slice.size());
  queue.Shutdown();
  while (queue.Next(&tag, &ok)) {
  }
  return raw;
}

TEST_F(ServerTest, TheStudyIsStoredAndServedAsTheBytesItsUserSent) {
  const v1::GetJobResponse reference = RunToEnd("reference.db", 7);
  const std::string sent = InReverseFieldOrder(OscillatorStudy());
  ASSERT_NE(sent, OscillatorStudy().SerializeAsString()) << "test setup: the bytes must not be canonical";
  v1::Study parsed;
  ASSERT_TRUE(parsed.ParseFromString(sent));
  ASSERT_EQ(parsed.SerializeAsString(), OscillatorStudy().SerializeAsString());

  auto server = StartServer("a.db");
  auto stub = v1::JobService::NewStub(server->InProcessChannel());
  grpc::ClientContext context;
  v1::SubmitJobRequest request;
  request.set_study(sent);
  request.set_source_name("oscillator.study.textproto");
  v1::SubmitJobResponse response;
  ASSERT_TRUE(stub->Submit(&context, request, &response).ok());
  const std::string id = response.job_id();

  absl::StatusOr<store::JobRow> row = server->store().GetJob(id);
  ASSERT_TRUE(row.ok()) << row.status();
  EXPECT_TRUE(row->study == sent) << "the stored study is not the bytes sent (" << row->study.size() << " bytes)";
  // A worker's GetStudy: field 1 (the study) holds the same bytes.
  google::protobuf::UnknownFieldSet served;
  ASSERT_TRUE(served.ParseFromString(RawGetStudyResponse(*server, id)));
  ASSERT_EQ(served.field_count(), 1);
  EXPECT_EQ(served.field(0).number(), v1::GetStudyResponse::kStudyFieldNumber);
  ASSERT_EQ(served.field(0).type(), google::protobuf::UnknownField::TYPE_LENGTH_DELIMITED);
  EXPECT_TRUE(served.field(0).length_delimited() == sent) << "GetStudy served other bytes than those sent";
  // Readers get it too, and the run is the canonical study's, record for record.
  FakeWorker worker(server->InProcessChannel(), 7);
  worker.Run();
  const v1::GetJobResponse job = Get(*server, id);
  EXPECT_EQ(job.study().SerializeAsString(), OscillatorStudy().SerializeAsString());
  ExpectSameCycles(reference, job);
}

}  // namespace
}  // namespace mbopt::service

namespace mbopt::service {
namespace {

// Calls held open (here watches of a job that waits for workers) cannot
// make the server start threads without end: beyond its quota a call is
// refused with RESOURCE_EXHAUSTED, and once the held calls end the server
// answers again.
TEST_F(ServerTest, CallsBeyondTheThreadQuotaAreRefusedAndTheServerAnswersOnceTheyEnd) {
  ServerOptions options;
  options.listen_address = "127.0.0.1:0";
  options.db_path = (dir_ / "a.db").string();
  options.clock = &clock_;
  options.max_call_threads = 12;
  absl::StatusOr<std::unique_ptr<MboptServer>> started = MboptServer::Start(options);
  ASSERT_TRUE(started.ok()) << started.status();
  MboptServer& server = **started;
  const std::string id = Submit(server, OscillatorStudy());
  constexpr int kWatchers = 40;
  std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
  std::vector<grpc::StatusCode> codes(kWatchers, grpc::StatusCode::OK);
  std::atomic<int> ended{0};
  std::vector<std::thread> watchers;
  for (int i = 0; i < kWatchers; ++i) contexts.push_back(std::make_unique<grpc::ClientContext>());
  for (int i = 0; i < kWatchers; ++i) {
    watchers.emplace_back([&, i] {
      auto stub = v1::JobService::NewStub(server.InProcessChannel());
      v1::JobRef ref;
      ref.set_job_id(id);
      auto reader = stub->Watch(contexts[static_cast<size_t>(i)].get(), ref);
      v1::JobEvent event;
      while (reader->Read(&event)) {
      }
      codes[static_cast<size_t>(i)] = reader->Finish().error_code();
      ++ended;
    });
  }
  // The refused ones end by themselves; the others stay open.
  for (int waited_ms = 0; waited_ms < 10'000 && ended.load() == 0; waited_ms += 20) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const int refused_while_held = ended.load();
  for (auto& context : contexts) context->TryCancel();
  for (std::thread& watcher : watchers) watcher.join();
  const int exhausted = static_cast<int>(std::count(codes.begin(), codes.end(), grpc::StatusCode::RESOURCE_EXHAUSTED));
  EXPECT_GT(refused_while_held, 0);
  EXPECT_GT(exhausted, 0);
  EXPECT_LT(exhausted, kWatchers);  // some were served
  // The cancelled watches' threads end at their next look at the call (a
  // watch waits for changes in slices); then the server answers.
  grpc::Status status;
  for (int waited_ms = 0; waited_ms < 10'000; waited_ms += 50) {
    auto stub = v1::JobService::NewStub(server.InProcessChannel());
    grpc::ClientContext context;
    v1::JobRef ref;
    ref.set_job_id(id);
    v1::GetJobResponse response;
    status = stub->Get(&context, ref, &response);
    if (status.ok()) {
      EXPECT_EQ(response.summary().job_id(), id);
      break;
    }
    EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_TRUE(status.ok()) << status.error_message();
}

}  // namespace
}  // namespace mbopt::service

namespace mbopt::service {
namespace {

// One address cannot hold more calls open than its share: the watches
// beyond the limit are refused naming it, and the address's calls are
// taken again once the held ones end.
TEST_F(ServerTest, WatchesBeyondAnAddresssHeldCallLimitAreRefusedNamingIt) {
  ServerOptions options;
  options.listen_address = "127.0.0.1:0";
  options.db_path = (dir_ / "a.db").string();
  options.clock = &clock_;
  options.max_held_calls_per_peer = 4;
  absl::StatusOr<std::unique_ptr<MboptServer>> started = MboptServer::Start(options);
  ASSERT_TRUE(started.ok()) << started.status();
  MboptServer& server = **started;
  const std::string id = Submit(server, OscillatorStudy());
  auto channel = grpc::CreateChannel(absl::StrCat("127.0.0.1:", server.port()), grpc::InsecureChannelCredentials());
  auto stub = v1::JobService::NewStub(channel);
  v1::JobRef ref;
  ref.set_job_id(id);
  constexpr int kWatches = 8;
  std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
  std::vector<std::unique_ptr<grpc::ClientReader<v1::JobEvent>>> readers;
  int served = 0, refused = 0;
  for (int i = 0; i < kWatches; ++i) {
    contexts.push_back(std::make_unique<grpc::ClientContext>());
    readers.push_back(stub->Watch(contexts.back().get(), ref));
    v1::JobEvent event;
    // A served watch sends the job's summary at once; a refused one ends.
    if (readers.back()->Read(&event)) {
      ++served;
    } else {
      const grpc::Status status = readers.back()->Finish();
      EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
      EXPECT_THAT(status.error_message(), HasSubstr("ipv4:127.0.0.1 holds 4 calls open"));
      ++refused;
    }
  }
  EXPECT_EQ(served, 4);
  EXPECT_EQ(refused, kWatches - 4);
  // Short calls are not held: they go on.
  EXPECT_EQ(Get(server, id).summary().job_id(), id);
  for (int i = 0; i < kWatches; ++i) contexts[static_cast<size_t>(i)]->TryCancel();
  readers.clear();
  // The cancelled watches give their places back when their handlers see
  // the cancellation (a watch waits in slices).
  bool watched_again = false;
  for (int waited_ms = 0; waited_ms < 10'000 && !watched_again; waited_ms += 50) {
    grpc::ClientContext context;
    auto reader = stub->Watch(&context, ref);
    v1::JobEvent event;
    watched_again = reader->Read(&event);
    context.TryCancel();
    reader->Finish();
    if (!watched_again) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_TRUE(watched_again);
}

}  // namespace
}  // namespace mbopt::service
