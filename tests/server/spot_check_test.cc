// Spot checks (mbopt-server --verify-fraction) in process: a worker that
// lies about one value is outvoted by two honest ones and quarantined, and
// the job ends with the records of an honest run, bit for bit.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include "mbopt/v1/service.grpc.pb.h"
#include "server/jobs/manager/spot_check.h"
#include "server/scheduler/clock.h"
#include "server/scheduler/scheduler.h"
#include "server/service/server.h"
#include "tests/server/fake_worker.h"
#include "tests/server/test_study.h"

namespace mbopt::service {
namespace {

using ::mbopt::testing::FakeWorker;
using ::mbopt::testing::OscillatorStudy;
using ::testing::HasSubstr;

TEST(SpotChecked, TheShareIsNearTheFractionAndTheChoiceDependsOnlyOnJobAndRequest) {
  int checked = 0;
  for (std::int64_t id = 0; id < 4000; ++id) {
    const bool once = jobs::manager::SpotChecked("job-1a2b3c4d5e6f", id, 0.25);
    EXPECT_EQ(once, jobs::manager::SpotChecked("job-1a2b3c4d5e6f", id, 0.25)) << id;
    checked += once ? 1 : 0;
    EXPECT_FALSE(jobs::manager::SpotChecked("job-1a2b3c4d5e6f", id, 0.0));
    EXPECT_TRUE(jobs::manager::SpotChecked("job-1a2b3c4d5e6f", id, 1.0));
  }
  // 1000 expected; the binomial's standard deviation is 27.
  EXPECT_GT(checked, 880);
  EXPECT_LT(checked, 1120);
  // Another job checks other analyses.
  int same = 0;
  for (std::int64_t id = 0; id < 4000; ++id) {
    same += jobs::manager::SpotChecked("job-1", id, 0.5) == jobs::manager::SpotChecked("job-2", id, 0.5) ? 1 : 0;
  }
  EXPECT_LT(same, 2200);
  EXPECT_GT(same, 1800);
}

class SpotCheckTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("mbopt_spot_") + info->name() + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::unique_ptr<MboptServer> StartServer(const std::string& db_name, double verify_fraction) {
    ServerOptions options;
    options.listen_address = "127.0.0.1:0";
    options.db_path = (dir_ / db_name).string();
    options.clock = &clock_;
    options.manager.verify_fraction = verify_fraction;
    absl::StatusOr<std::unique_ptr<MboptServer>> server = MboptServer::Start(options);
    EXPECT_TRUE(server.ok()) << server.status();
    return server.ok() ? *std::move(server) : nullptr;
  }
  static std::string Submit(MboptServer& server) {
    auto jobs = v1::JobService::NewStub(server.InProcessChannel());
    grpc::ClientContext context;
    v1::SubmitJobRequest request;
    request.set_study(OscillatorStudy().SerializeAsString());
    v1::SubmitJobResponse response;
    EXPECT_TRUE(jobs->Submit(&context, request, &response).ok());
    return response.job_id();
  }
  static v1::GetJobResponse Get(MboptServer& server, const std::string& job_id) {
    auto jobs = v1::JobService::NewStub(server.InProcessChannel());
    grpc::ClientContext context;
    v1::JobRef ref;
    ref.set_job_id(job_id);
    v1::GetJobResponse response;
    EXPECT_TRUE(jobs->Get(&context, ref, &response).ok());
    return response;
  }
  static v1::ListWorkersResponse Workers(MboptServer& server) {
    auto jobs = v1::JobService::NewStub(server.InProcessChannel());
    grpc::ClientContext context;
    v1::ListWorkersResponse response;
    EXPECT_TRUE(jobs->ListWorkers(&context, v1::ListWorkersRequest(), &response).ok());
    return response;
  }

  // The records of a run without spot checks, by one honest worker.
  v1::GetJobResponse HonestRun() {
    std::unique_ptr<MboptServer> server = StartServer("honest.db", 0.0);
    const std::string job_id = Submit(*server);
    FakeWorker worker(server->InProcessChannel(), 7);
    worker.Run();
    return Get(*server, job_id);
  }

  // Each worker in turn takes one task and answers it, until none is on
  // offer; `liar`'s answers have their first objective term one ulp off.
  static void Drive(const std::vector<FakeWorker*>& workers, const FakeWorker* liar) {
    for (int round = 0; round < 100'000; ++round) {
      bool answered = false;
      for (FakeWorker* worker : workers) {
        for (const v1::AnalysisTask& task : worker->Acquire(1)) {
          v1::TaskResult result = worker->ResultOf(task);
          if (worker == liar && result.objective_terms_size() > 0) {
            result.set_objective_terms(0, std::nextafter(result.objective_terms(0),
                                                         std::numeric_limits<double>::infinity()));
          }
          grpc::ClientContext context;
          v1::ReportResultResponse response;
          const grpc::Status status = worker->stub().ReportResult(&context, result, &response);
          EXPECT_TRUE(status.ok()) << status.error_message();
          answered = true;
        }
      }
      if (!answered) return;
    }
    ADD_FAILURE() << "the workers never ran out of tasks";
  }

  scheduler::FakeClock clock_;
  std::filesystem::path dir_;
};

TEST_F(SpotCheckTest, ALyingWorkerIsOutvotedAndQuarantinedAndTheJobEndsAsAnHonestRun) {
  const v1::GetJobResponse honest = HonestRun();
  ASSERT_EQ(honest.summary().state(), v1::JOB_STATE_CONVERGED);

  std::unique_ptr<MboptServer> server = StartServer("checked.db", 1.0);
  const std::string job_id = Submit(*server);
  ::testing::internal::CaptureStderr();
  FakeWorker liar(server->InProcessChannel(), 1, "liar");
  FakeWorker first(server->InProcessChannel(), 2, "honest-1");
  FakeWorker second(server->InProcessChannel(), 3, "honest-2");
  Drive({&liar, &first, &second}, &liar);
  const std::string log = ::testing::internal::GetCapturedStderr();

  const v1::GetJobResponse checked = Get(*server, job_id);
  EXPECT_EQ(checked.summary().state(), v1::JOB_STATE_CONVERGED) << checked.summary().message();
  ASSERT_EQ(checked.cycles_size(), honest.cycles_size());
  for (int i = 0; i < checked.cycles_size(); ++i) {
    EXPECT_EQ(checked.cycles(i).SerializeAsString(), honest.cycles(i).SerializeAsString()) << "record " << i;
  }
  EXPECT_EQ(checked.summary().analyses(), honest.summary().analyses());

  const std::string liar_id = scheduler::PublicWorkerId(liar.worker_id());
  absl::StatusOr<std::vector<jobs::AnalysisRecord>> logged = server->store().LoadAnalyses(job_id);
  ASSERT_TRUE(logged.ok()) << logged.status();
  for (const jobs::AnalysisRecord& analysis : *logged) {
    EXPECT_NE(analysis.worker, liar_id) << "analysis " << analysis.request_id << " was taken from the liar";
  }

  const v1::ListWorkersResponse workers = Workers(*server);
  ASSERT_EQ(workers.workers_size(), 3);
  EXPECT_TRUE(workers.workers(0).quarantined());
  EXPECT_FALSE(workers.workers(1).quarantined());
  EXPECT_FALSE(workers.workers(2).quarantined());
  EXPECT_TRUE(liar.Acquire(10).empty()) << "a quarantined worker gets no tasks";

  absl::StatusOr<std::vector<store::EventRow>> events = server->store().LoadEvents(job_id);
  ASSERT_TRUE(events.ok()) << events.status();
  std::string quarantined, differ;
  for (const store::EventRow& event : *events) {
    if (event.kind == "quarantined") quarantined = event.message;
    if (event.kind == "spot check" && event.message.find("differ") != std::string::npos) differ = event.message;
  }
  EXPECT_THAT(quarantined, HasSubstr("worker " + liar_id + " quarantined: its answer to analysis "));
  EXPECT_THAT(quarantined, HasSubstr("which agree"));
  EXPECT_THAT(differ, HasSubstr(liar_id));
  EXPECT_THAT(differ, HasSubstr("another worker decides"));
  EXPECT_THAT(log, HasSubstr("WARNING: worker " + liar_id + " QUARANTINED"));
}

// With a fifth of the analyses checked, the liar's first answers are taken
// unchecked (job-1's first two requests are not among the fifth) before it
// is caught; then they are taken back with what the job did after them,
// computed again by the honest workers, and the job still ends with an
// honest run's records.
TEST_F(SpotCheckTest, ACaughtLiarsUncheckedAnswersAreTakenBackAndComputedAgain) {
  const v1::GetJobResponse honest = HonestRun();
  std::unique_ptr<MboptServer> server = StartServer("checked.db", 0.2);
  const std::string job_id = Submit(*server);
  ::testing::internal::CaptureStderr();
  FakeWorker liar(server->InProcessChannel(), 1, "liar");
  FakeWorker first(server->InProcessChannel(), 2, "honest-1");
  FakeWorker second(server->InProcessChannel(), 3, "honest-2");
  Drive({&liar, &first, &second}, &liar);
  ::testing::internal::GetCapturedStderr();
  ASSERT_EQ(job_id, "job-1") << "the test relies on which of job-1's requests are checked";
  ASSERT_FALSE(jobs::manager::SpotChecked(job_id, 0, 0.2));
  const v1::GetJobResponse checked = Get(*server, job_id);
  EXPECT_EQ(checked.summary().state(), v1::JOB_STATE_CONVERGED) << checked.summary().message();
  ASSERT_EQ(checked.cycles_size(), honest.cycles_size());
  for (int i = 0; i < checked.cycles_size(); ++i) {
    EXPECT_EQ(checked.cycles(i).SerializeAsString(), honest.cycles(i).SerializeAsString()) << "record " << i;
  }
  const std::string liar_id = scheduler::PublicWorkerId(liar.worker_id());
  const v1::ListWorkersResponse workers = Workers(*server);
  ASSERT_EQ(workers.workers_size(), 3);
  EXPECT_TRUE(workers.workers(0).quarantined());
  absl::StatusOr<std::vector<jobs::AnalysisRecord>> logged = server->store().LoadAnalyses(job_id);
  ASSERT_TRUE(logged.ok()) << logged.status();
  for (const jobs::AnalysisRecord& analysis : *logged) EXPECT_NE(analysis.worker, liar_id) << analysis.request_id;
  absl::StatusOr<std::vector<store::EventRow>> events = server->store().LoadEvents(job_id);
  ASSERT_TRUE(events.ok()) << events.status();
  std::string quarantined;
  for (const store::EventRow& event : *events) {
    if (event.kind == "quarantined") quarantined = event.message;
  }
  EXPECT_THAT(quarantined, HasSubstr("its unchecked answers here are taken back"));
}

// With honest workers, checking every other analysis costs analyses but
// changes nothing in the records, and nobody is quarantined.
TEST_F(SpotCheckTest, HonestWorkersPassEveryCheckAndTheRecordsAreThoseOfARunWithout) {
  const v1::GetJobResponse honest = HonestRun();
  std::unique_ptr<MboptServer> server = StartServer("checked.db", 0.5);
  const std::string job_id = Submit(*server);
  FakeWorker first(server->InProcessChannel(), 2, "honest-1");
  FakeWorker second(server->InProcessChannel(), 3, "honest-2");
  Drive({&first, &second}, nullptr);
  const v1::GetJobResponse checked = Get(*server, job_id);
  ASSERT_EQ(checked.cycles_size(), honest.cycles_size());
  for (int i = 0; i < checked.cycles_size(); ++i) {
    EXPECT_EQ(checked.cycles(i).SerializeAsString(), honest.cycles(i).SerializeAsString()) << "record " << i;
  }
  const int answers = static_cast<int>(first.answered_request_ids().size() + second.answered_request_ids().size());
  EXPECT_GT(answers, honest.summary().analyses()) << "some analyses were checked";
  const v1::ListWorkersResponse workers = Workers(*server);
  for (const v1::WorkerSummary& worker : workers.workers()) EXPECT_FALSE(worker.quarantined());
}

}  // namespace
}  // namespace mbopt::service
