#include "tests/fuzz/result_intake_check.h"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "mbopt/v1/service.pb.h"
#include "mbopt/v1/study.pb.h"
#include "server/jobs/job_state.h"
#include "server/jobs/manager/job_manager.h"
#include "server/jobs/record_codec.h"
#include "server/lp/make_clp_lp_solver.h"
#include "server/scheduler/clock.h"
#include "server/scheduler/scheduler.h"
#include "server/service/proto_convert.h"
#include "server/store/store.h"
#include "tests/server/test_study.h"

namespace mbopt::fuzz {
namespace {

// Enough for a batch to touch both jobs' tasks several times over; more
// only slows each input down.
constexpr int kMaxResultsPerBatch = 64;
// Rounds of honest answers a job may need to end after a hostile batch
// (the oscillator converges in about ten cycles of three analyses).
constexpr int kMaxHonestRounds = 400;

[[noreturn]] void Fail(const std::string& what) {
  std::cerr << "fuzz check failed: result intake: " << what << std::endl;
  std::abort();
}

// The codes a refusal of a worker's result may carry (service.proto's
// ResultAnswer.error): anything else is a finding.
bool IsExpectedRefusal(const absl::Status& status) {
  switch (status.code()) {
    case absl::StatusCode::kInvalidArgument:
    case absl::StatusCode::kPermissionDenied:
    case absl::StatusCode::kNotFound:
    case absl::StatusCode::kFailedPrecondition:
      return true;
    default:
      return false;
  }
}

// A directory of this process for the databases of the checks.
const std::filesystem::path& WorkDirectory() {
  static const std::filesystem::path dir = [] {
    std::filesystem::path path = std::filesystem::temp_directory_path() /
                                 absl::StrCat("mbopt-result-intake-", ::getpid());
    std::filesystem::create_directories(path);
    return path;
  }();
  return dir;
}

// A server without its network: the store, the scheduler and the job manager
// of mboptserver.cc, on a database file that outlives it.
struct Server {
  scheduler::FakeClock clock;
  std::unique_ptr<store::Store> store;
  std::unique_ptr<scheduler::Scheduler> scheduler;
  std::unique_ptr<jobs::manager::JobManager> manager;

  explicit Server(const std::string& db_path) {
    absl::StatusOr<std::unique_ptr<store::Store>> opened = store::Store::Open(db_path, store::Durability::kNormal);
    if (!opened.ok()) Fail(absl::StrCat("the store does not open: ", opened.status().ToString()));
    store = *std::move(opened);
    scheduler = std::make_unique<scheduler::Scheduler>(&clock, scheduler::SchedulerOptions{});
    jobs::manager::JobManagerOptions options;
    options.clock = &clock;
    options.make_lp_solver = [] { return lp::MakeClpLpSolver(); };
    manager = std::make_unique<jobs::manager::JobManager>(store.get(), scheduler.get(), &service::DecodeStudy,
                                                          options);
    if (absl::Status started = manager->Start(); !started.ok()) {
      Fail(absl::StrCat("the server does not start: ", started.ToString()));
    }
  }
  ~Server() {
    manager->Shutdown();
    manager.reset();
    scheduler->Shutdown();
  }
};

struct World {
  std::map<std::string, v1::Study> studies;  // by job id
  std::string holder;                        // the worker holding every lease
  std::string other;                         // a registered worker holding none
  std::vector<scheduler::Task> leased;
};

World StartJobs(Server& server) {
  World world;
  for (const v1::Study& study : {testing::OscillatorStudy("fd"), testing::OscillatorStudyWithSensitivities("sens")}) {
    absl::StatusOr<std::string> job_id = server.manager->Submit(study.SerializeAsString(), "fuzz.study");
    if (!job_id.ok()) Fail(absl::StrCat("the oscillator study is refused: ", job_id.status().ToString()));
    world.studies[*job_id] = study;
  }
  world.holder = server.scheduler->RegisterWorker("holder", 8);
  world.other = server.scheduler->RegisterWorker("other", 8);
  absl::StatusOr<std::vector<scheduler::Task>> tasks = server.scheduler->Acquire(world.holder, 1000);
  if (!tasks.ok() || tasks->empty()) Fail("no task on offer after two submits");
  world.leased = *std::move(tasks);
  return world;
}

// The world's values for a result's empty fields (result_intake_check.h).
void FillFromWorld(const World& world, int index, v1::TaskResult& result) {
  if (result.worker_id().empty()) {
    result.set_worker_id(world.holder);
  } else if (result.worker_id() == "B") {
    result.set_worker_id(world.other);
  }
  const std::string& task_id = result.task_id();
  if (task_id.empty() || task_id[0] == '#') {
    long long k = index;
    if (task_id.size() > 1) k = std::strtoll(task_id.c_str() + 1, nullptr, 10);
    const size_t n = world.leased.size();
    const scheduler::Task& task = world.leased[static_cast<size_t>(k < 0 ? -(k + 1) : k) % n];
    result.set_task_id(task.task_id);
    if (result.request_id() == 0) result.set_request_id(task.request_id);
    if (result.job_id().empty()) result.set_job_id(task.job_id);
  }
}

// What the service does with a batch (WorkerServiceImpl::TakeResults): a
// retry goes to ReportWorkerError, the rest to the intake together.
std::vector<absl::StatusOr<bool>> Deliver(jobs::manager::JobManager& manager, const v1::TaskResults& batch) {
  std::vector<absl::StatusOr<bool>> answers(static_cast<size_t>(batch.results_size()), false);
  std::vector<jobs::manager::WorkerReport> reports;
  std::vector<size_t> report_index;
  for (int i = 0; i < batch.results_size(); ++i) {
    const v1::TaskResult& result = batch.results(i);
    if (result.retry()) {
      const absl::Status reported =
          manager.ReportWorkerError(result.worker_id(), result.task_id(), result.failure_reason());
      answers[static_cast<size_t>(i)] = absl::IsNotFound(reported) ? absl::StatusOr<bool>(false)
                                        : reported.ok()            ? absl::StatusOr<bool>(true)
                                                                   : absl::StatusOr<bool>(reported);
      continue;
    }
    reports.push_back(service::WorkerReportFromProto(result, /*holder=*/""));
    report_index.push_back(static_cast<size_t>(i));
  }
  std::vector<absl::StatusOr<bool>> taken = manager.ReportResults(std::move(reports));
  for (size_t k = 0; k < taken.size(); ++k) answers[report_index[k]] = std::move(taken[k]);
  return answers;
}

struct JobSnapshot {
  std::int64_t version = 0;
  jobs::JobState state = jobs::JobState::kQueued;
  std::vector<std::string> records;  // encoded
};

std::map<std::string, JobSnapshot> Snapshot(jobs::manager::JobManager& manager, const World& world) {
  std::map<std::string, JobSnapshot> out;
  for (const auto& [job_id, study] : world.studies) {
    absl::StatusOr<jobs::manager::JobView> view = manager.Get(job_id);
    if (!view.ok()) Fail(absl::StrCat("job ", job_id, " cannot be read: ", view.status().ToString()));
    JobSnapshot& snapshot = out[job_id];
    snapshot.version = view->version;
    snapshot.state = view->summary.state;
    for (const slp::CycleRecord& record : view->records) snapshot.records.push_back(jobs::EncodeCycleRecord(record));
  }
  return out;
}

// The result an honest worker sends for `task`.
v1::TaskResult HonestResult(const World& world, const std::string& worker_id, const scheduler::Task& task) {
  const v1::Study& study = world.studies.at(task.job_id);
  v1::TaskResult result;
  result.set_worker_id(worker_id);
  result.set_task_id(task.task_id);
  result.set_job_id(task.job_id);
  result.set_request_id(task.request_id);
  absl::StatusOr<testing::FakeValues> values = testing::EvaluateAnalytically(study, task.x_scaled);
  if (!values.ok()) {
    result.set_ok(false);
    result.set_failure_reason(std::string(values.status().message()));
    return result;
  }
  result.set_ok(true);
  for (double v : values->objective_terms) result.add_objective_terms(v);
  for (double v : values->constraint_values) result.add_constraint_values(v);
  if (task.want_gradients) {
    absl::StatusOr<testing::FakeGradients> gradients = testing::GradientsAnalytically(study, task.x_scaled);
    if (gradients.ok()) {
      for (double v : gradients->objective_gradients) result.add_objective_gradients(v);
      for (double v : gradients->constraint_gradients) result.add_constraint_gradients(v);
    }
  }
  return result;
}

void CheckAnswers(const v1::TaskResults& batch, const std::vector<absl::StatusOr<bool>>& answers) {
  for (size_t i = 0; i < answers.size(); ++i) {
    if (!answers[i].ok() && !IsExpectedRefusal(answers[i].status())) {
      Fail(absl::StrCat("result ", i, " (task '", batch.results(static_cast<int>(i)).task_id(),
                        "') is answered with an unexpected status: ", answers[i].status().ToString()));
    }
  }
}

// Nobody in the batch holds a lease: nothing may change.
void CheckNothingChanged(const std::map<std::string, JobSnapshot>& before,
                         const std::map<std::string, JobSnapshot>& after, int leased_before, int leased_after,
                         const std::vector<absl::StatusOr<bool>>& answers) {
  for (size_t i = 0; i < answers.size(); ++i) {
    if (answers[i].ok() && *answers[i]) Fail(absl::StrCat("result ", i, " of a worker without its lease was taken"));
  }
  if (leased_before != leased_after) {
    Fail(absl::StrCat("results of workers without leases changed the leases held: ", leased_before, " -> ",
                      leased_after));
  }
  for (const auto& [job_id, snapshot] : before) {
    if (after.at(job_id).version != snapshot.version) {
      Fail(absl::StrCat("results of workers without leases changed job ", job_id));
    }
  }
}

// After a restart on the same database, every job replays to the records it
// had, and a running job is still running.
void CheckReplay(const std::map<std::string, JobSnapshot>& before, const std::map<std::string, JobSnapshot>& after) {
  for (const auto& [job_id, snapshot] : before) {
    const JobSnapshot& again = after.at(job_id);
    if (snapshot.state == jobs::JobState::kRunning && again.state != jobs::JobState::kRunning) {
      Fail(absl::StrCat("job ", job_id, " was running and is ", jobs::JobStateName(again.state),
                        " after a restart: its logged results do not replay"));
    }
    if (again.records.size() < snapshot.records.size()) {
      Fail(absl::StrCat("job ", job_id, " had ", snapshot.records.size(), " cycle records and ",
                        again.records.size(), " after a restart"));
    }
    for (size_t k = 0; k < snapshot.records.size(); ++k) {
      if (again.records[k] != snapshot.records[k]) {
        Fail(absl::StrCat("job ", job_id, "'s cycle record ", k, " differs after a restart"));
      }
    }
  }
}

// Honest answers take every job to its end.
void CheckJobsEnd(Server& server, const World& world) {
  const std::string worker = server.scheduler->RegisterWorker("honest", 8);
  for (int round = 0; round < kMaxHonestRounds; ++round) {
    absl::StatusOr<std::vector<scheduler::Task>> tasks = server.scheduler->Acquire(worker, 64);
    if (!tasks.ok()) Fail(absl::StrCat("an honest worker cannot take tasks: ", tasks.status().ToString()));
    if (tasks->empty()) break;
    v1::TaskResults batch;
    for (const scheduler::Task& task : *tasks) *batch.add_results() = HonestResult(world, worker, task);
    const std::vector<absl::StatusOr<bool>> answers = Deliver(*server.manager, batch);
    for (size_t i = 0; i < answers.size(); ++i) {
      if (!answers[i].ok()) {
        Fail(absl::StrCat("an honest result is refused: ", answers[i].status().ToString()));
      }
    }
  }
  for (const auto& [job_id, study] : world.studies) {
    absl::StatusOr<jobs::manager::JobView> view = server.manager->Get(job_id);
    if (!view.ok()) Fail(absl::StrCat("job ", job_id, " cannot be read: ", view.status().ToString()));
    if (!jobs::IsFinished(view->summary.state)) {
      Fail(absl::StrCat("job ", job_id, " is ", jobs::JobStateName(view->summary.state), " (", view->summary.message,
                        ") with no task on offer after honest answers: it is stuck"));
    }
  }
}

void RemoveDatabase(const std::string& db_path) {
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) std::filesystem::remove(db_path + suffix);
}

}  // namespace

void CheckResultIntake(std::string_view data) {
  v1::TaskResults batch;
  // Not a message: gRPC refuses it before any service code sees it.
  if (!batch.ParseFromArray(data.data(), static_cast<int>(data.size()))) return;
  if (batch.results_size() > kMaxResultsPerBatch) return;
  const std::string db_path = (WorkDirectory() / "intake.db").string();
  RemoveDatabase(db_path);
  World world;
  std::map<std::string, JobSnapshot> after_batch;
  {
    Server server(db_path);
    world = StartJobs(server);
    bool any_holder = false;
    for (int i = 0; i < batch.results_size(); ++i) {
      FillFromWorld(world, i, *batch.mutable_results(i));
      any_holder = any_holder || batch.results(i).worker_id() == world.holder;
    }
    const std::map<std::string, JobSnapshot> before = Snapshot(*server.manager, world);
    const int leased_before = server.scheduler->LeasedCount();
    std::vector<std::string> heartbeat_ids;
    for (const v1::TaskResult& result : batch.results()) heartbeat_ids.push_back(result.task_id());
    if (!batch.results().empty()) server.scheduler->Heartbeat(batch.results(0).worker_id(), heartbeat_ids);
    const std::vector<absl::StatusOr<bool>> answers = Deliver(*server.manager, batch);
    CheckAnswers(batch, answers);
    after_batch = Snapshot(*server.manager, world);
    if (!any_holder) {
      CheckNothingChanged(before, after_batch, leased_before, server.scheduler->LeasedCount(), answers);
    }
  }
  Server restarted(db_path);
  CheckReplay(after_batch, Snapshot(*restarted.manager, world));
  CheckJobsEnd(restarted, world);
}

std::vector<std::string> ResultIntakeSeeds() {
  // The honest answers to the first tasks, as the world of the check makes
  // them (ids left empty: the check fills them).
  const std::string db_path = (WorkDirectory() / "seeds.db").string();
  RemoveDatabase(db_path);
  std::vector<std::string> seeds;
  {
    Server server(db_path);
    const World world = StartJobs(server);
    v1::TaskResults honest;
    for (size_t k = 0; k < world.leased.size(); ++k) {
      v1::TaskResult result = HonestResult(world, "", world.leased[k]);
      result.set_task_id(absl::StrCat("#", k));
      result.clear_job_id();
      result.clear_request_id();
      *honest.add_results() = result;
    }
    seeds.push_back(honest.SerializeAsString());
    // The first alone, by the other worker (not its lease).
    v1::TaskResults foreign;
    *foreign.add_results() = honest.results(0);
    foreign.mutable_results(0)->set_worker_id("B");
    seeds.push_back(foreign.SerializeAsString());
    // A failed analysis and a retry.
    v1::TaskResults failed;
    v1::TaskResult* failure = failed.add_results();
    failure->set_task_id("#0");
    failure->set_ok(false);
    failure->set_failure_kind(v1::ANALYSIS_FAILURE_INTEGRATOR);
    failure->set_failure_reason("corrector convergence failed");
    v1::TaskResult* retry = failed.add_results();
    retry->set_task_id("#1");
    retry->set_retry(true);
    retry->set_failure_reason("worker out of memory");
    seeds.push_back(failed.SerializeAsString());
  }
  RemoveDatabase(db_path);
  return seeds;
}

}  // namespace mbopt::fuzz
