// The worker's evaluation of tasks and its conversation with a server, the
// latter against a fake WorkerService on a real loopback port (port 0).
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <future>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include "common/packed_doubles/packed_doubles.h"

#include "mbopt/v1/service.grpc.pb.h"
#include "spec/io/study_io.h"
#include "tests/testing/fake_clock.h"
#include "worker/budget/analysis_budget.h"
#include "worker/engine/study_sensitivities.h"
#include "worker/service/task_evaluator.h"
#include "worker/service/worker_service.h"

namespace mbopt::worker {
namespace {

constexpr auto kGuard = std::chrono::seconds(60);  // failure guard only

std::string VehicleStudyPath() {
  return std::string(MBOPT_TEST_SOURCE_DIR) + "/examples/vehicle/vehicle.study.textproto";
}

v1::Study VehicleStudyProto() {
  auto study = spec::io::ReadStudyProto(VehicleStudyPath());
  EXPECT_TRUE(study.ok()) << study.status();
  return study.ok() ? *study : v1::Study();
}

v1::AnalysisTask TaskAt(const std::vector<double>& x) {
  v1::AnalysisTask task;
  task.set_task_id("job-1/0/0");
  task.set_job_id("job-1");
  for (double v : x) task.add_x_scaled(v);
  return task;
}

// A result's values as the worker packed them (empty if they do not unpack).
std::vector<double> Unpacked(const std::string& packed_values) {
  absl::StatusOr<std::vector<double>> values = packed::UnpackDoubles(packed_values, 1 << 24);
  EXPECT_TRUE(values.ok()) << values.status();
  return values.ok() ? *values : std::vector<double>{};
}

std::vector<double> InitialDesign(const v1::Study& study) {
  std::vector<double> x;
  for (const auto& v : study.variables()) x.push_back(v.initial());
  return x;
}

TEST(TaskEvaluator, ValuesAlignWithTheStudyLayout) {
  const v1::Study proto = VehicleStudyProto();
  auto prepared = PrepareStudy(proto, "job-1");
  ASSERT_TRUE(prepared.ok()) << prepared.status();
  v1::TaskResult result;
  EvaluateTask(**prepared, TaskAt(InitialDesign(proto)), ValueEncoding::kPacked, &result);
  ASSERT_TRUE(result.ok()) << result.failure_reason();
  // Sent packed only.
  EXPECT_EQ(result.objective_terms_size(), 0);
  EXPECT_EQ(result.constraint_values_size(), 0);
  EXPECT_EQ(Unpacked(result.objective_terms_packed()).size(),
            static_cast<size_t>((*prepared)->layout.num_objective_terms()));
  EXPECT_EQ(Unpacked(result.constraint_values_packed()).size(),
            static_cast<size_t>((*prepared)->layout.num_constraints()));
  EXPECT_FALSE(result.formulation().empty());
  for (double v : Unpacked(result.objective_terms_packed())) EXPECT_TRUE(std::isfinite(v));
}

// A worker that cannot run an external study's driver says so, and the task
// goes back for another worker (retry) instead of failing the design.
TEST(TaskEvaluator, AnExternalStudyIsRunnableOnlyWhereItsDriverIsDeclared) {
  auto study = spec::io::LoadStudyFile(std::string(MBOPT_TEST_SOURCE_DIR) +
                                       "/examples/external/quarter_car.study.textproto");
  ASSERT_TRUE(study.ok()) << study.status();
  EXPECT_NE(CannotRun(*study, nullptr).find("declares no drivers"), std::string::npos);
  external::ExternalWorkerSettings settings;
  settings.drivers.resize(1);
  settings.drivers[0].name = "other";
  EXPECT_NE(CannotRun(*study, &settings).find("no driver \"quarter_car\"; it declares: \"other\""),
            std::string::npos)
      << CannotRun(*study, &settings);
  settings.drivers[0].name = "quarter_car";
  EXPECT_EQ(CannotRun(*study, &settings), "");
  auto vehicle = spec::io::LoadStudyFile(VehicleStudyPath());
  ASSERT_TRUE(vehicle.ok());
  EXPECT_EQ(CannotRun(*vehicle, nullptr), "") << "built-in scenes need no drivers";
}

TEST(TaskEvaluator, WrongDimensionIsAFailedResultNotACrash) {
  const v1::Study proto = VehicleStudyProto();
  auto prepared = PrepareStudy(proto, "job-1");
  ASSERT_TRUE(prepared.ok()) << prepared.status();
  v1::TaskResult result;
  EvaluateTask(**prepared, TaskAt({1.0}), ValueEncoding::kPacked, &result);
  EXPECT_FALSE(result.ok());
  EXPECT_NE(result.failure_reason().find("design variables"), std::string::npos)
      << result.failure_reason();
  EXPECT_EQ(result.failure_kind(), v1::ANALYSIS_FAILURE_SERVICE);
}

TEST(TaskEvaluator, NonFiniteInputsOrValuesAreFailedResults) {
  const v1::Study proto = VehicleStudyProto();
  auto prepared = PrepareStudy(proto, "job-1");
  ASSERT_TRUE(prepared.ok()) << prepared.status();
  std::vector<double> x = InitialDesign(proto);
  x[0] = std::numeric_limits<double>::quiet_NaN();
  v1::TaskResult result;
  EvaluateTask(**prepared, TaskAt(x), ValueEncoding::kPacked, &result);
  EXPECT_FALSE(result.ok());
  EXPECT_EQ(result.objective_terms_size(), 0);
  EXPECT_TRUE(result.objective_terms_packed().empty());
  EXPECT_TRUE(result.constraint_values_packed().empty());
  // Absurd stiffnesses: the analysis either fails or overflows; both must
  // come back as a failure with a reason, never as values.
  std::vector<double> huge(x.size(), 1e300);
  v1::TaskResult overflow;
  EvaluateTask(**prepared, TaskAt(huge), ValueEncoding::kPacked, &overflow);
  EXPECT_FALSE(overflow.ok());
  EXPECT_FALSE(overflow.failure_reason().empty());
  // A kind the server can count: never "unspecified" for a failed result.
  EXPECT_NE(overflow.failure_kind(), v1::ANALYSIS_FAILURE_KIND_UNSPECIFIED) << overflow.failure_reason();
}

TEST(TaskEvaluator, NoGradientsUnlessTheTaskAsks) {
  const v1::Study proto = VehicleStudyProto();
  auto prepared = PrepareStudy(proto, "job-1");
  ASSERT_TRUE(prepared.ok()) << prepared.status();
  v1::TaskResult result;
  EvaluateTask(**prepared, TaskAt(InitialDesign(proto)), ValueEncoding::kPacked, &result);
  ASSERT_TRUE(result.ok()) << result.failure_reason();
  EXPECT_EQ(result.objective_gradients_size(), 0);
  EXPECT_EQ(result.constraint_gradients_size(), 0);
  EXPECT_EQ(result.gradients_unavailable(), "");
}

// The result carries the engine's gradients row-major, bit for bit, and
// the same values as the engine's sensitivity analysis.
TEST(TaskEvaluator, GradientsWhenAskedAreTheEnginesRowMajor) {
  const v1::Study proto = VehicleStudyProto();
  auto prepared = PrepareStudy(proto, "job-1");
  ASSERT_TRUE(prepared.ok()) << prepared.status();
  const std::vector<double> x = InitialDesign(proto);
  v1::AnalysisTask task = TaskAt(x);
  task.set_want_gradients(true);
  v1::TaskResult result;
  EvaluateTask(**prepared, task, ValueEncoding::kPacked, &result);
  ASSERT_TRUE(result.ok()) << result.failure_reason();
  EXPECT_EQ(result.gradients_unavailable(), "");
  const size_t n = x.size();
  const auto& layout = (*prepared)->layout;
  ASSERT_EQ(static_cast<size_t>(result.objective_gradients_size()),
            static_cast<size_t>(layout.num_objective_terms()) * n);
  ASSERT_EQ(static_cast<size_t>(result.constraint_gradients_size()),
            static_cast<size_t>(layout.num_constraints()) * n);

  const engine::StudyAnalysisWithGradients engine =
      engine::AnalyzeStudyWithGradients((*prepared)->study, layout, x);
  ASSERT_TRUE(engine.gradients.has_value()) << engine.gradients_unavailable;
  for (size_t k = 0; k < engine.gradients->objective_terms.size(); ++k) {
    for (size_t i = 0; i < n; ++i) {
      ASSERT_EQ(result.objective_gradients(static_cast<int>(k * n + i)), engine.gradients->objective_terms[k][i])
          << "term " << k << ", variable " << i;
    }
  }
  for (size_t h = 0; h < engine.gradients->constraint_rows.size(); ++h) {
    for (size_t i = 0; i < n; ++i) {
      ASSERT_EQ(result.constraint_gradients(static_cast<int>(h * n + i)), engine.gradients->constraint_rows[h][i])
          << "row " << h << ", variable " << i;
    }
  }
  // Deterministic: the same task gives the same bits again.
  v1::TaskResult again;
  EvaluateTask(**prepared, task, ValueEncoding::kPacked, &again);
  ASSERT_EQ(again.objective_gradients_size(), result.objective_gradients_size());
  ASSERT_EQ(again.constraint_gradients_size(), result.constraint_gradients_size());
  EXPECT_EQ(std::memcmp(again.objective_gradients().data(), result.objective_gradients().data(),
                        sizeof(double) * static_cast<size_t>(result.objective_gradients_size())),
            0);
  EXPECT_EQ(std::memcmp(again.constraint_gradients().data(), result.constraint_gradients().data(),
                        sizeof(double) * static_cast<size_t>(result.constraint_gradients_size())),
            0);
}

// A design variable that sets the vehicle's speed (a ground input) has no
// simulator sensitivity: the task still gets its values, with the reason.
TEST(TaskEvaluator, StudyWithoutSimulatorSensitivitiesGivesValuesAndTheReason) {
  v1::Study proto = VehicleStudyProto();
  auto* speed = proto.mutable_variables(0);
  speed->set_name("v");
  speed->set_parameter("speed");
  speed->set_scale(100);
  speed->set_initial(10.56);
  speed->set_lower(5);
  speed->set_upper(20);
  auto prepared = PrepareStudy(proto, "job-1");
  ASSERT_TRUE(prepared.ok()) << prepared.status();
  v1::AnalysisTask task = TaskAt(InitialDesign(proto));
  task.set_want_gradients(true);
  v1::TaskResult result;
  EvaluateTask(**prepared, task, ValueEncoding::kPacked, &result);
  ASSERT_TRUE(result.ok()) << result.failure_reason();
  EXPECT_EQ(Unpacked(result.objective_terms_packed()).size(),
            static_cast<size_t>((*prepared)->layout.num_objective_terms()));
  EXPECT_EQ(result.objective_gradients_size(), 0);
  EXPECT_EQ(result.constraint_gradients_size(), 0);
  EXPECT_NE(result.gradients_unavailable().find("speed"), std::string::npos) << result.gradients_unavailable();
}

// A task whose cancel flag is up ends as a `cancelled` failure (the worker
// then drops it), not as values or another kind of failure.
TEST(TaskEvaluator, CancelledAnalysisIsACancelledFailure) {
  const v1::Study proto = VehicleStudyProto();
  auto prepared = PrepareStudy(proto, "job-1");
  ASSERT_TRUE(prepared.ok()) << prepared.status();
  const mbopt::testing::CancelAfter cancel(50);
  v1::TaskResult result;
  EvaluateTask(**prepared, TaskAt(InitialDesign(proto)), ValueEncoding::kPacked, &result, nullptr,
               budget::AnalysisBudget(nullptr, cancel.AsFlag()));
  EXPECT_FALSE(result.ok());
  EXPECT_EQ(result.failure_kind(), v1::ANALYSIS_FAILURE_CANCELLED) << result.failure_reason();
  EXPECT_NE(result.failure_reason().find("cancelled at t = "), std::string::npos) << result.failure_reason();
  EXPECT_GE(cancel.asked(), 50);
}

TEST(TaskEvaluator, StudyThatDoesNotConvertIsAnError) {
  v1::Study proto = VehicleStudyProto();
  proto.mutable_variables(0)->set_parameter("no_such_parameter");
  EXPECT_FALSE(PrepareStudy(proto, "job-1").ok());
}

// A WorkerService that hands out the tasks the test queues and records what
// the worker sends back.
class FakeWorkerService final : public v1::WorkerService::Service {
 public:
  explicit FakeWorkerService(v1::Study study) : study_(std::move(study)) {}

  grpc::Status Register(grpc::ServerContext*, const v1::RegisterWorkerRequest* request,
                        v1::RegisterWorkerResponse* response) override {
    std::lock_guard<std::mutex> lock(mutex_);
    ++registrations_;
    slots_ = request->slots();
    response->set_worker_id("w-" + std::to_string(registrations_));
    response->set_heartbeat_interval_ms(20);
    response->set_lease_ms(10000);
    cv_.notify_all();
    return grpc::Status::OK;
  }

  grpc::Status AcquireTasks(grpc::ServerContext* context, const v1::AcquireTasksRequest* request,
                            v1::AcquireTasksResponse* response) override {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait_for(lock, std::chrono::milliseconds(request->wait_ms()),
                 [&] { return !tasks_.empty() || context->IsCancelled(); });
    while (!tasks_.empty() && response->tasks_size() < request->max_tasks()) {
      *response->add_tasks() = tasks_.front();
      tasks_.erase(tasks_.begin());
    }
    return grpc::Status::OK;
  }

  grpc::Status GetStudy(grpc::ServerContext*, const v1::GetStudyRequest*,
                        v1::GetStudyResponse* response) override {
    std::lock_guard<std::mutex> lock(mutex_);
    ++study_fetches_;
    *response->mutable_study() = study_;
    return grpc::Status::OK;
  }

  grpc::Status ReportResult(grpc::ServerContext*, const v1::TaskResult* result,
                            v1::ReportResultResponse* response) override {
    std::lock_guard<std::mutex> lock(mutex_);
    results_.push_back(*result);
    response->set_accepted(true);
    cv_.notify_all();
    return grpc::Status::OK;
  }

  grpc::Status ReportResults(grpc::ServerContext*, const v1::TaskResults* request,
                             v1::ReportResultsResponse* response) override {
    std::lock_guard<std::mutex> lock(mutex_);
    report_calls_.push_back(request->results_size());
    for (const v1::TaskResult& result : request->results()) {
      results_.push_back(result);
      response->add_answers()->set_accepted(true);
    }
    cv_.notify_all();
    return grpc::Status::OK;
  }

  grpc::Status Heartbeat(grpc::ServerContext*, const v1::HeartbeatRequest*,
                         v1::HeartbeatResponse* response) override {
    std::lock_guard<std::mutex> lock(mutex_);
    ++heartbeats_;
    // The first heartbeat says "who are you?", as a restarted server would.
    response->set_known(heartbeats_ > 1);
    // Tasks of cancelled jobs, once the worker has the study (it is then
    // running the first of them).
    if (study_fetches_ > 0) {
      for (const std::string& task_id : cancel_) response->add_cancelled_task_ids(task_id);
    }
    cv_.notify_all();
    return grpc::Status::OK;
  }

  void Queue(const v1::AnalysisTask& task) {
    std::lock_guard<std::mutex> lock(mutex_);
    tasks_.push_back(task);
    cv_.notify_all();
  }

  // Waits (guarded) until `predicate` holds under the lock.
  template <typename P>
  bool WaitUntil(P predicate) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, kGuard, [&] { return predicate(*this); });
  }

  std::mutex mutex_;
  std::condition_variable cv_;
  v1::Study study_;
  std::vector<v1::AnalysisTask> tasks_;
  std::vector<v1::TaskResult> results_;
  std::vector<int> report_calls_;  // results per ReportResults call
  int registrations_ = 0;
  int heartbeats_ = 0;
  int study_fetches_ = 0;
  int slots_ = 0;
  std::vector<std::string> cancel_;  // task ids every heartbeat says are cancelled
};

// The fake on 127.0.0.1 (any free port, in *port); nullptr if it cannot start.
std::unique_ptr<grpc::Server> ServeOnLoopback(FakeWorkerService& fake, int* port) {
  grpc::ServerBuilder builder;
  builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), port);
  builder.RegisterService(&fake);
  std::unique_ptr<grpc::Server> server = builder.BuildAndStart();
  return server != nullptr && *port > 0 ? std::move(server) : nullptr;
}

TEST(WorkerService, EvaluatesTasksFetchesTheStudyOnceAndRegistersAgainWhenForgotten) {
  const v1::Study proto = VehicleStudyProto();
  FakeWorkerService fake(proto);
  int port = 0;
  std::unique_ptr<grpc::Server> server = ServeOnLoopback(fake, &port);
  ASSERT_NE(server, nullptr);

  WorkerOptions options;
  options.server_address = "127.0.0.1:" + std::to_string(port);
  options.slots = 2;
  options.name = "test-worker";
  options.acquire_wait_ms = 200;
  StopSignal stop;
  absl::Status run_status;
  std::thread worker([&] { run_status = RunWorker(options, stop); });

  const std::vector<double> x0 = InitialDesign(proto);
  for (int i = 0; i < 3; ++i) {
    v1::AnalysisTask task = TaskAt(x0);
    task.set_task_id("job-1/" + std::to_string(i) + "/0");
    task.set_request_id(i);
    fake.Queue(task);
  }
  EXPECT_TRUE(fake.WaitUntil([](FakeWorkerService& f) {
    return f.results_.size() == 3 && f.registrations_ >= 2;
  })) << "results and a second registration after known = false";
  stop.Stop();
  worker.join();
  EXPECT_TRUE(run_status.ok()) << run_status;
  // Before taking the fake's lock: Shutdown() waits for in-flight handlers,
  // and a long poll the worker abandoned may still be waiting for that lock.
  server->Shutdown();

  std::lock_guard<std::mutex> lock(fake.mutex_);
  EXPECT_EQ(fake.slots_, 2);
  EXPECT_EQ(fake.study_fetches_, 1) << "one study fetch per job";
  for (const auto& r : fake.results_) {
    EXPECT_TRUE(r.ok()) << r.failure_reason();
    EXPECT_EQ(r.job_id(), "job-1");
    // Identical inputs, identical outputs: bit identity is the point.
    // The fake announces no packed values, as a server from before them:
    // it gets them unpacked.
    EXPECT_TRUE(r.objective_terms_packed().empty());
    ASSERT_GT(r.objective_terms_size(), 0);
    ASSERT_EQ(r.constraint_values_size(), fake.results_[0].constraint_values_size());
    EXPECT_EQ(r.objective_terms(0), fake.results_[0].objective_terms(0));
  }
}

// Tasks handed out together run back to back and their results go back in
// one call; with --batch 1, or when each analysis takes longer than a cheap
// one (here held 150 ms), each goes back alone.
TEST(WorkerService, TasksHandedOutTogetherAreReportedTogether) {
  const v1::Study proto = VehicleStudyProto();
  struct Case {
    int batch;
    int task_delay_ms;
    std::vector<int> calls;  // results per ReportResults call
  };
  for (const Case& c : {Case{16, 0, {5}}, Case{1, 0, {1, 1, 1, 1, 1}}, Case{16, 150, {1, 1, 1, 1, 1}}}) {
    SCOPED_TRACE(::testing::Message() << "batch " << c.batch << ", delay " << c.task_delay_ms << " ms");
    FakeWorkerService fake(proto);
    int port = 0;
    std::unique_ptr<grpc::Server> server = ServeOnLoopback(fake, &port);
    ASSERT_NE(server, nullptr);
    const std::vector<double> x0 = InitialDesign(proto);
    for (int i = 0; i < 5; ++i) {
      v1::AnalysisTask task = TaskAt(x0);
      task.set_task_id("job-1/" + std::to_string(i) + "/1");
      task.set_request_id(i);
      fake.Queue(task);
    }
    WorkerOptions options;
    options.server_address = "127.0.0.1:" + std::to_string(port);
    options.slots = 1;
    options.batch = c.batch;
    options.task_delay_ms = c.task_delay_ms;
    options.acquire_wait_ms = 200;
    StopSignal stop;
    absl::Status run_status;
    std::thread worker([&] { run_status = RunWorker(options, stop); });
    EXPECT_TRUE(fake.WaitUntil([](FakeWorkerService& f) { return f.results_.size() == 5; }));
    stop.Stop();
    worker.join();
    EXPECT_TRUE(run_status.ok()) << run_status;
    server->Shutdown();
    std::lock_guard<std::mutex> lock(fake.mutex_);
    EXPECT_EQ(fake.report_calls_, c.calls);
    ASSERT_EQ(fake.results_.size(), 5u);
    for (int i = 0; i < 5; ++i) EXPECT_EQ(fake.results_[static_cast<size_t>(i)].request_id(), i) << "in the order run";
  }
}

// The vehicle without any damping, over 10^7 s: CVODES follows every
// oscillation of the wheel hop (about 10 Hz) and would spend its 10^8 steps,
// minutes of work, before the analysis ended. A heartbeat saying the task
// is cancelled stops it within a budget check: the worker's one slot is
// free for the next task long before that, and the cancelled task's result
// is not sent.
TEST(WorkerService, CancelledTaskStopsItsRunningAnalysis) {
  v1::Study proto = VehicleStudyProto();
  v1::Scene& scene = *proto.mutable_scene();
  scene.mutable_time_grid()->set_end_s(1e7);
  scene.mutable_integrator()->set_max_steps(100'000'000);
  scene.mutable_integrator()->set_max_wall_seconds(3600);
  for (v1::Parameter& p : *scene.mutable_parameters()) {
    if (p.name() == "c4" || p.name() == "c5") p.set_value(0.0);  // tyres
  }
  FakeWorkerService fake(proto);
  int port = 0;
  std::unique_ptr<grpc::Server> server = ServeOnLoopback(fake, &port);
  ASSERT_NE(server, nullptr);
  std::vector<double> undamped = InitialDesign(proto);
  for (const char* damper : {"x4", "x5", "x6"}) {
    for (int i = 0; i < proto.variables_size(); ++i) {
      if (proto.variables(i).name() == damper) undamped[static_cast<size_t>(i)] = 0.0;
    }
  }
  v1::AnalysisTask endless = TaskAt(undamped);
  endless.set_task_id("job-1/0/0");
  v1::AnalysisTask next = TaskAt(InitialDesign(proto));
  next.set_task_id("job-1/0/1");
  next.set_request_id(1);
  fake.cancel_ = {endless.task_id()};
  fake.Queue(endless);
  fake.Queue(next);

  WorkerOptions options;
  options.server_address = "127.0.0.1:" + std::to_string(port);
  options.slots = 1;
  options.batch = 1;
  options.acquire_wait_ms = 200;
  StopSignal stop;
  absl::Status run_status;
  std::thread worker([&] { run_status = RunWorker(options, stop); });
  const auto start = std::chrono::steady_clock::now();
  const bool next_done = fake.WaitUntil([](FakeWorkerService& f) { return !f.results_.empty(); });
  const double waited_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  stop.Stop();
  worker.join();
  EXPECT_TRUE(run_status.ok()) << run_status;
  server->Shutdown();
  ASSERT_TRUE(next_done) << "the cancelled analysis kept the only slot for " << waited_s << " s";
  std::lock_guard<std::mutex> lock(fake.mutex_);
  ASSERT_EQ(fake.results_.size(), 1u);
  EXPECT_EQ(fake.results_[0].task_id(), next.task_id()) << "the cancelled task's result is dropped";
  EXPECT_TRUE(fake.results_[0].ok()) << fake.results_[0].failure_reason();
}

TEST(WorkerService, RejectsBadOptions) {
  StopSignal stop;
  WorkerOptions options;
  EXPECT_FALSE(RunWorker(options, stop).ok()) << "no server address";
  options.server_address = "127.0.0.1:1";
  options.slots = 0;
  EXPECT_FALSE(RunWorker(options, stop).ok()) << "zero slots";
}

// A worker that cannot reach its server waits before trying again (the
// backoff); a stop request must end that wait. The stop comes once the
// worker is in that wait (the stop signal reports each wait and its length;
// the heartbeat thread's waits are shorter), and the backoff is far longer
// than the guard, so only the stop can end it in time.
TEST(WorkerService, StopsWhileTheServerIsUnreachable) {
  constexpr auto kBackoff = std::chrono::milliseconds(60'000);
  constexpr auto kFailureGuard = std::chrono::seconds(20);  // a working stop takes milliseconds
  WorkerOptions options;
  options.server_address = "127.0.0.1:1";  // nothing listens there
  options.backoff.initial = kBackoff;
  options.backoff.max = kBackoff;
  options.backoff.jitter = 0.0;
  StopSignal stop;
  std::promise<void> in_backoff;
  std::once_flag in_backoff_once;
  stop.OnWaitBlocks([&](std::chrono::milliseconds timeout) {
    if (timeout == kBackoff) std::call_once(in_backoff_once, [&] { in_backoff.set_value(); });
  });
  std::promise<absl::Status> ran;
  std::future<absl::Status> run_status = ran.get_future();
  std::thread worker([&] { ran.set_value(RunWorker(options, stop)); });

  const bool worker_waits = in_backoff.get_future().wait_for(kFailureGuard) == std::future_status::ready;
  stop.Stop();
  const bool worker_returned = run_status.wait_for(kFailureGuard) == std::future_status::ready;
  worker.join();  // at the latest when the backoff ends

  ASSERT_TRUE(worker_waits) << "the worker never began its reconnection backoff";
  ASSERT_TRUE(worker_returned) << "the worker still waited out its backoff 20 s after the stop request";
  const absl::Status status = run_status.get();
  EXPECT_TRUE(status.ok()) << status;
}

}  // namespace
}  // namespace mbopt::worker
