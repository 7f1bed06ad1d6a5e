// The task queue: fairness between jobs, leases and their expiry, heartbeats
// and the retry limit, on a fake clock (no test waits for real time).
#include "server/scheduler/scheduler.h"

#include <chrono>
#include <future>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace mbopt::scheduler {
namespace {

constexpr std::int64_t kLeaseMs = 1000;

SchedulerOptions Options() {
  SchedulerOptions options;
  options.lease_ms = kLeaseMs;
  options.heartbeat_interval_ms = 200;
  options.max_attempts = 3;
  return options;
}

TEST(Scheduler, HandsOutTasksRoundRobinBetweenJobs) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  for (int r = 0; r < 10; ++r) scheduler.Enqueue("job-1", r, {1.0});
  for (int r = 0; r < 2; ++r) scheduler.Enqueue("job-2", r, {2.0});
  for (int r = 0; r < 2; ++r) scheduler.Enqueue("job-3", r, {3.0});
  const std::string worker = scheduler.RegisterWorker("w", 1);
  auto tasks = scheduler.Acquire(worker, 6);
  ASSERT_TRUE(tasks.ok());
  ASSERT_EQ(tasks->size(), 6u);
  std::map<std::string, int> per_job;
  for (const Task& t : *tasks) per_job[t.job_id] += 1;
  // Each of the three jobs gets two of the first six tasks, although job-1
  // queued five times as many.
  EXPECT_EQ(per_job["job-1"], 2);
  EXPECT_EQ(per_job["job-2"], 2);
  EXPECT_EQ(per_job["job-3"], 2);
  // Consecutive tasks come from different jobs.
  for (size_t i = 1; i < tasks->size(); ++i) EXPECT_NE((*tasks)[i].job_id, (*tasks)[i - 1].job_id);
  // Then the long job gets the rest, in request order.
  auto rest = scheduler.Acquire(worker, 100);
  ASSERT_TRUE(rest.ok());
  ASSERT_EQ(rest->size(), 8u);
  for (size_t i = 0; i < rest->size(); ++i) {
    EXPECT_EQ((*rest)[i].job_id, "job-1");
    EXPECT_EQ((*rest)[i].request_id, static_cast<std::int64_t>(i + 2));
  }
}

// Spot checks: an answer held for a check sends its task to a worker that
// has not answered it (never back to the one that did), which may then
// complete it; the first worker cannot complete it. A quarantined worker
// gets no task, its lease is queued again, and its results are refused.
TEST(Scheduler, ACheckedTaskGoesToAnotherWorkerAndAQuarantinedWorkerGetsNothing) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  scheduler.Enqueue("job-1", 0, {1.0});
  scheduler.Enqueue("job-1", 1, {2.0});
  const std::string first = scheduler.RegisterWorker("first", 1);
  const std::string second = scheduler.RegisterWorker("second", 1);
  auto task = scheduler.Acquire(first, 1);
  ASSERT_TRUE(task.ok() && task->size() == 1u);
  EXPECT_TRUE(scheduler.HasLiveWorkerBesides({first}));
  EXPECT_FALSE(scheduler.HasLiveWorkerBesides({first, second}));
  ASSERT_TRUE(scheduler.AskAnotherWorker(first, (*task)[0].task_id).ok());
  // The first worker is offered the other request only.
  auto again = scheduler.Acquire(first, 5);
  ASSERT_TRUE(again.ok());
  ASSERT_EQ(again->size(), 1u);
  EXPECT_EQ((*again)[0].request_id, 1);
  EXPECT_EQ(scheduler.Complete(first, (*task)[0].task_id).status().code(), absl::StatusCode::kNotFound);
  auto checked = scheduler.Acquire(second, 1);
  ASSERT_TRUE(checked.ok() && checked->size() == 1u);
  EXPECT_EQ((*checked)[0].request_id, 0);
  EXPECT_EQ((*checked)[0].attempt, 2);
  EXPECT_TRUE(scheduler.Complete(second, (*checked)[0].task_id).ok());

  // The first worker holds request 1 when it is quarantined.
  const std::optional<std::vector<FinishedTask>> given_up = scheduler.Quarantine(first);
  ASSERT_TRUE(given_up.has_value());
  EXPECT_TRUE(given_up->empty());
  EXPECT_FALSE(scheduler.Quarantine(first).has_value()) << "already quarantined";
  EXPECT_TRUE(scheduler.Acquire(first, 5)->empty());
  EXPECT_EQ(scheduler.Complete(first, (*again)[0].task_id).status().code(), absl::StatusCode::kPermissionDenied);
  auto requeued = scheduler.Acquire(second, 1);
  ASSERT_TRUE(requeued.ok() && requeued->size() == 1u);
  EXPECT_EQ((*requeued)[0].request_id, 1);
  const std::vector<WorkerView> workers = scheduler.Workers();
  ASSERT_EQ(workers.size(), 2u);
  EXPECT_TRUE(workers[0].quarantined);
  EXPECT_FALSE(workers[1].quarantined);
}

// A job whose scene names an analysis driver goes only to workers that
// declared it; other jobs' tasks still go to everyone.
// An FMU study's tasks go only to workers that load FMUs (a platform at
// registration); with none registered the study is not refused (every
// worker build loads them), its tasks wait.
TEST(Scheduler, FmuTasksGoOnlyToWorkersThatLoadFmus) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  TaskNeeds fmu_needs;
  fmu_needs.loads_fmus = true;
  EXPECT_FALSE(scheduler.SomeWorkerCan(fmu_needs));
  EXPECT_EQ(fmu_needs.Describe(), "FMU support (a platform it loads FMUs for)");
  scheduler.SetJobNeeds("job-fmu", fmu_needs);
  scheduler.Enqueue("job-fmu", 0, {1.0});
  const std::string without = scheduler.RegisterWorker("no-fmu", 1);
  auto none = scheduler.Acquire(without, 10);
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->empty());
  EXPECT_FALSE(scheduler.SomeWorkerCan(fmu_needs));
  const std::string with = scheduler.RegisterWorker("fmu", 1, WorkerCapabilities{{}, "linux64"});
  EXPECT_TRUE(scheduler.SomeWorkerCan(fmu_needs));
  auto tasks = scheduler.Acquire(with, 10);
  ASSERT_TRUE(tasks.ok());
  ASSERT_EQ(tasks->size(), 1u);
  EXPECT_EQ((*tasks)[0].job_id, "job-fmu");
}

// An FMU the study carries has binaries for some platforms only: its tasks
// go to a worker that loads one of those, never to one that loads FMUs for
// another platform, and until such a worker registers the job waits.
TEST(Scheduler, FmuTasksGoOnlyToWorkersThatLoadOneOfTheFmusPlatforms) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  TaskNeeds needs;
  needs.loads_fmus = true;
  needs.fmu_platforms = {"darwin64", "win64"};
  EXPECT_EQ(needs.Describe(), "FMU support for darwin64 or win64 (the platforms the FMU has binaries for)");
  scheduler.SetJobNeeds("job-fmu", needs);
  scheduler.Enqueue("job-fmu", 0, {1.0});
  const std::string linux_worker = scheduler.RegisterWorker("linux", 1, WorkerCapabilities{{}, "linux64"});
  EXPECT_FALSE(scheduler.SomeWorkerCan(needs));
  auto none = scheduler.Acquire(linux_worker, 10);
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->empty()) << "a linux64 worker cannot load an FMU without linux64 binaries";
  const std::string windows_worker = scheduler.RegisterWorker("windows", 1, WorkerCapabilities{{}, "win64"});
  EXPECT_TRUE(scheduler.SomeWorkerCan(needs));
  auto tasks = scheduler.Acquire(windows_worker, 10);
  ASSERT_TRUE(tasks.ok());
  ASSERT_EQ(tasks->size(), 1u);
  EXPECT_EQ((*tasks)[0].job_id, "job-fmu");
  // Without the FMU's platforms (a study that names the file only), any
  // worker that loads FMUs will do.
  needs.fmu_platforms.clear();
  EXPECT_TRUE(needs.RunnableBy(WorkerCapabilities{{}, "linux64"}));
  EXPECT_FALSE(needs.RunnableBy(WorkerCapabilities{{}, ""}));
}

TEST(Scheduler, TasksThatNeedADriverGoOnlyToWorkersThatDeclareIt) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  scheduler.SetJobNeeds("job-ext", TaskNeeds{"quarter_car"});
  for (int r = 0; r < 3; ++r) scheduler.Enqueue("job-ext", r, {1.0});
  scheduler.Enqueue("job-plain", 0, {2.0});
  const std::string plain = scheduler.RegisterWorker("plain", 1);
  const std::string able = scheduler.RegisterWorker("able", 1, WorkerCapabilities{{"other", "quarter_car"}, ""});
  auto to_plain = scheduler.Acquire(plain, 10);
  ASSERT_TRUE(to_plain.ok());
  ASSERT_EQ(to_plain->size(), 1u);
  EXPECT_EQ((*to_plain)[0].job_id, "job-plain");
  // Nothing left that the plain worker can run.
  auto again = scheduler.Acquire(plain, 10);
  ASSERT_TRUE(again.ok());
  EXPECT_TRUE(again->empty());
  // A batch is the worker's share by slots of all the work outstanding
  // (two of four), the rest once it has answered one.
  auto to_able = scheduler.Acquire(able, 10);
  ASSERT_TRUE(to_able.ok());
  ASSERT_EQ(to_able->size(), 2u);
  ASSERT_TRUE(scheduler.Complete(able, (*to_able)[0].task_id).ok());
  auto rest = scheduler.Acquire(able, 10);
  ASSERT_TRUE(rest.ok());
  ASSERT_EQ(rest->size(), 1u);
  to_able->push_back(rest->front());
  for (const Task& t : *to_able) EXPECT_EQ(t.job_id, "job-ext");
  ASSERT_TRUE(scheduler.Complete(plain, (*to_plain)[0].task_id).ok());

  // What `mbopt workers` shows, and what submit checks.
  const std::vector<WorkerView> workers = scheduler.Workers();
  ASSERT_EQ(workers.size(), 2u);
  EXPECT_EQ(workers[0].name, "plain");
  EXPECT_EQ(workers[0].public_id, PublicWorkerId(plain));
  EXPECT_EQ(workers[0].analyses_done, 1);
  EXPECT_EQ(workers[0].tasks_held, 0);
  EXPECT_EQ(workers[1].name, "able");
  EXPECT_EQ(workers[1].capabilities.drivers, (std::vector<std::string>{"other", "quarter_car"}));
  EXPECT_EQ(workers[1].analyses_done, 1);
  EXPECT_EQ(workers[1].tasks_held, 2);
  EXPECT_EQ(scheduler.OfferedDrivers(), (std::vector<std::string>{"other", "quarter_car"}));
  EXPECT_TRUE(scheduler.SomeWorkerCan(TaskNeeds{"quarter_car"}));
  EXPECT_FALSE(scheduler.SomeWorkerCan(TaskNeeds{"missing"}));
  EXPECT_TRUE(scheduler.SomeWorkerCan(TaskNeeds{}));
}

// Until a worker that declares the driver registers, the job's tasks wait;
// dropping the job forgets what it needed.
TEST(Scheduler, ADriversTasksWaitForAWorkerThatDeclaresIt) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  scheduler.SetJobNeeds("job-ext", TaskNeeds{"quarter_car"});
  scheduler.Enqueue("job-ext", 0, {1.0});
  const std::string plain = scheduler.RegisterWorker("plain", 1);
  EXPECT_FALSE(scheduler.SomeWorkerCan(TaskNeeds{"quarter_car"}));
  auto none = scheduler.Acquire(plain, 1);
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->empty());
  EXPECT_EQ(scheduler.QueuedCount(), 1);
  const std::string able = scheduler.RegisterWorker("able", 1, WorkerCapabilities{{"quarter_car"}, ""});
  auto one = scheduler.Acquire(able, 1);
  ASSERT_TRUE(one.ok());
  EXPECT_EQ(one->size(), 1u);
  scheduler.DropJob("job-ext");
  scheduler.Enqueue("job-ext", 1, {1.0});
  auto after_drop = scheduler.Acquire(plain, 1);
  ASSERT_TRUE(after_drop.ok());
  EXPECT_EQ(after_drop->size(), 1u) << "a dropped job's needs are forgotten";
}

// A worker that asks for a batch gets its share, by slots, of the work
// outstanding, never fewer than its free slots: the others are not left idle.
TEST(Scheduler, BatchesAreTheWorkersShareOfTheOutstandingTasks) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  for (int r = 0; r < 9; ++r) scheduler.Enqueue("job-1", r, {});
  const std::string a = scheduler.RegisterWorker("a", 1);
  const std::string b = scheduler.RegisterWorker("b", 1);
  EXPECT_EQ(scheduler.Acquire(a, 64)->size(), 5u) << "ceil(9 / 2)";
  EXPECT_EQ(scheduler.Acquire(a, 64)->size(), 0u) << "a holds its share";
  EXPECT_EQ(scheduler.Acquire(b, 64)->size(), 4u);
  // Alone (b's slots are gone with b), a worker takes everything.
  scheduler.WorkerLost(b);
  EXPECT_EQ(scheduler.Acquire(a, 64)->size(), 4u) << "b's tasks, queued again";

  Scheduler weighted(&clock, Options());
  for (int r = 0; r < 9; ++r) weighted.Enqueue("job-1", r, {});
  const std::string big = weighted.RegisterWorker("big", 2);
  const std::string small = weighted.RegisterWorker("small", 1);
  EXPECT_EQ(weighted.Acquire(big, 64)->size(), 6u) << "ceil(9 * 2 / 3)";
  EXPECT_EQ(weighted.Acquire(small, 64)->size(), 3u);
  // A free slot always gets a task, whatever the shares.
  weighted.Enqueue("job-1", 9, {});
  EXPECT_EQ(weighted.Acquire(small, 1)->size(), 1u);
}

TEST(Scheduler, FairnessHoldsAcrossSeparateAcquireCalls) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  for (int r = 0; r < 4; ++r) scheduler.Enqueue("job-1", r, {});
  for (int r = 0; r < 4; ++r) scheduler.Enqueue("job-2", r, {});
  const std::string worker = scheduler.RegisterWorker("w", 1);
  std::string previous;
  for (int i = 0; i < 8; ++i) {
    auto tasks = scheduler.Acquire(worker, 1);
    ASSERT_TRUE(tasks.ok());
    ASSERT_EQ(tasks->size(), 1u);
    EXPECT_NE(tasks->front().job_id, previous);
    previous = tasks->front().job_id;
  }
}

TEST(Scheduler, EnqueueIgnoresRequestsAlreadyQueuedLeasedOrFinished) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  EXPECT_TRUE(scheduler.Enqueue("job-1", 0, {}));
  EXPECT_FALSE(scheduler.Enqueue("job-1", 0, {}));
  const std::string worker = scheduler.RegisterWorker("w", 1);
  auto tasks = scheduler.Acquire(worker, 1);
  ASSERT_TRUE(tasks.ok());
  EXPECT_FALSE(scheduler.Enqueue("job-1", 0, {}));
  ASSERT_TRUE(scheduler.Complete(worker, tasks->front().task_id).ok());
  EXPECT_FALSE(scheduler.Enqueue("job-1", 0, {}));
  EXPECT_EQ(scheduler.QueuedCount(), 0);
}

// Latency is real time from the first queueing to the result, whatever the
// injected clock says and however many attempts it took.
TEST(Scheduler, LatencyRunsFromTheFirstQueueingToTheResult) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  const auto before = std::chrono::steady_clock::now();
  ASSERT_TRUE(scheduler.Enqueue("job-1", 0, {0.5}));
  const std::string first = scheduler.RegisterWorker("first", 1);
  const std::string second = scheduler.RegisterWorker("second", 1);
  auto attempt = scheduler.Acquire(first, 1);
  ASSERT_TRUE(attempt.ok() && attempt->size() == 1u);
  ASSERT_TRUE(scheduler.Fail(first, attempt->front().task_id, "worker could not run it").ok());
  clock.Advance(3'600'000);  // the injected clock has no part in it
  auto retry = scheduler.Acquire(second, 1);
  ASSERT_TRUE(retry.ok() && retry->size() == 1u);
  absl::StatusOr<FinishedTask> done = scheduler.Complete(second, retry->front().task_id);
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count();
  ASSERT_TRUE(done.ok()) << done.status();
  EXPECT_EQ(done->attempts, 2);
  EXPECT_GT(done->latency_seconds, 0.0);
  EXPECT_LE(done->latency_seconds, elapsed);
}

TEST(Scheduler, ExpiredLeaseRequeuesTheTaskForAnotherWorker) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  scheduler.Enqueue("job-1", 5, {0.5});
  const std::string lost = scheduler.RegisterWorker("lost", 1);
  const std::string other = scheduler.RegisterWorker("other", 1);
  auto first = scheduler.Acquire(lost, 1);
  ASSERT_TRUE(first.ok());
  ASSERT_EQ(first->size(), 1u);
  EXPECT_EQ(first->front().lease_deadline_ms, clock.NowMs() + kLeaseMs);

  clock.Advance(kLeaseMs - 1);
  EXPECT_TRUE(scheduler.ExpireLeases().empty());
  EXPECT_EQ(scheduler.QueuedCount(), 0);
  clock.Advance(1);
  EXPECT_TRUE(scheduler.ExpireLeases().empty());  // re-queued, not given up
  EXPECT_EQ(scheduler.QueuedCount(), 1);
  EXPECT_EQ(scheduler.LeasedCount(), 0);

  // The worker that lost it is passed over while another is alive.
  auto again_lost = scheduler.Acquire(lost, 1);
  ASSERT_TRUE(again_lost.ok());
  EXPECT_TRUE(again_lost->empty());
  auto second = scheduler.Acquire(other, 1);
  ASSERT_TRUE(second.ok());
  ASSERT_EQ(second->size(), 1u);
  EXPECT_EQ(second->front().request_id, 5);
  EXPECT_EQ(second->front().attempt, 2);
  EXPECT_NE(second->front().task_id, first->front().task_id);
}

TEST(Scheduler, LostWorkerRequeuesItsTasksAtOnceAndIsForgotten) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  scheduler.Enqueue("job-1", 5, {0.5});
  scheduler.Enqueue("job-1", 6, {0.6});
  const std::string lost = scheduler.RegisterWorker("lost", 2);
  const std::string other = scheduler.RegisterWorker("other", 1);
  ASSERT_EQ(scheduler.Acquire(lost, 2)->size(), 2u);
  EXPECT_EQ(scheduler.QueuedCount(), 0);

  // No time passes: the connection closed, nothing waits for the lease.
  EXPECT_TRUE(scheduler.WorkerLost(lost).empty());  // re-queued, not given up
  EXPECT_EQ(scheduler.QueuedCount(), 2);
  EXPECT_EQ(scheduler.LeasedCount(), 0);
  EXPECT_FALSE(scheduler.IsKnownWorker(lost));
  EXPECT_TRUE(scheduler.IsKnownWorker(other));
  EXPECT_FALSE(scheduler.Heartbeat(lost, {}).known);  // a live one registers again
  auto retried = scheduler.Acquire(other, 1);
  ASSERT_TRUE(retried.ok());
  ASSERT_EQ(retried->size(), 1u);
  EXPECT_EQ(retried->front().attempt, 2);  // the lost attempt counts
  EXPECT_TRUE(scheduler.WorkerLost(lost).empty());  // already forgotten: nothing happens
}

TEST(Scheduler, LostWorkersUseUpAttemptsLikeExpiredLeases) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  scheduler.Enqueue("job-1", 0, {});
  std::vector<FinishedTask> given_up;
  for (int attempt = 1; attempt <= 3; ++attempt) {
    const std::string w = scheduler.RegisterWorker("crashes on this task", 1);
    ASSERT_EQ(scheduler.Acquire(w, 1)->size(), 1u);
    given_up = scheduler.WorkerLost(w);
  }
  ASSERT_EQ(given_up.size(), 1u);
  EXPECT_NE(given_up.front().failure_reason.find("disconnected"), std::string::npos)
      << given_up.front().failure_reason;
}

TEST(Scheduler, RetryGoesToTheSameWorkerWhenItIsTheOnlyOne) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  scheduler.Enqueue("job-1", 0, {});
  const std::string only = scheduler.RegisterWorker("only", 1);
  ASSERT_EQ(scheduler.Acquire(only, 1)->size(), 1u);
  clock.Advance(kLeaseMs);
  scheduler.ExpireLeases();
  auto retry = scheduler.Acquire(only, 1);
  ASSERT_TRUE(retry.ok());
  EXPECT_EQ(retry->size(), 1u);
}

TEST(Scheduler, HeartbeatExtendsTheLease) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  scheduler.Enqueue("job-1", 0, {});
  const std::string worker = scheduler.RegisterWorker("w", 1);
  auto tasks = scheduler.Acquire(worker, 1);
  ASSERT_TRUE(tasks.ok());
  const std::string task_id = tasks->front().task_id;
  for (int beat = 0; beat < 5; ++beat) {
    clock.Advance(kLeaseMs - 100);
    HeartbeatReply reply = scheduler.Heartbeat(worker, {task_id});
    EXPECT_TRUE(reply.known);
    EXPECT_TRUE(reply.cancelled_task_ids.empty());
    EXPECT_TRUE(scheduler.ExpireLeases().empty());
    EXPECT_EQ(scheduler.LeasedCount(), 1);
  }
  // Silence after the last heartbeat: the lease runs out.
  clock.Advance(kLeaseMs);
  scheduler.ExpireLeases();
  EXPECT_EQ(scheduler.LeasedCount(), 0);
  EXPECT_EQ(scheduler.QueuedCount(), 1);
}

TEST(Scheduler, HeartbeatOfUnknownWorkerAsksToRegisterAndCancelsStaleTasks) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  EXPECT_FALSE(scheduler.Heartbeat("w-99", {}).known);
  const std::string worker = scheduler.RegisterWorker("w", 1);
  HeartbeatReply reply = scheduler.Heartbeat(worker, {"job-1/0/1"});
  EXPECT_TRUE(reply.known);
  ASSERT_EQ(reply.cancelled_task_ids.size(), 1u);
  EXPECT_EQ(reply.cancelled_task_ids[0], "job-1/0/1");
}

TEST(Scheduler, TaskIsGivenUpAfterThreeFailedAttempts) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  scheduler.Enqueue("job-1", 3, {0.25});
  const std::string a = scheduler.RegisterWorker("a", 1);
  const std::string b = scheduler.RegisterWorker("b", 1);
  const std::string c = scheduler.RegisterWorker("c", 1);

  auto t1 = scheduler.Acquire(a, 1);
  ASSERT_EQ(t1->size(), 1u);
  auto fail1 = scheduler.Fail(a, t1->front().task_id, "out of memory");
  ASSERT_TRUE(fail1.ok());
  EXPECT_FALSE(fail1->has_value());

  auto t2 = scheduler.Acquire(b, 1);
  ASSERT_EQ(t2->size(), 1u);
  clock.Advance(kLeaseMs);
  EXPECT_TRUE(scheduler.ExpireLeases().empty());

  auto t3 = scheduler.Acquire(c, 1);
  ASSERT_EQ(t3->size(), 1u);
  EXPECT_EQ(t3->front().attempt, 3);
  clock.Advance(kLeaseMs);
  std::vector<FinishedTask> given_up = scheduler.ExpireLeases();
  ASSERT_EQ(given_up.size(), 1u);
  EXPECT_EQ(given_up[0].job_id, "job-1");
  EXPECT_EQ(given_up[0].request_id, 3);
  EXPECT_EQ(given_up[0].attempts, 3);
  EXPECT_NE(given_up[0].failure_reason.find("3 failed attempts"), std::string::npos);
  EXPECT_EQ(scheduler.QueuedCount(), 0);
  EXPECT_EQ(scheduler.LeasedCount(), 0);
  EXPECT_FALSE(scheduler.Enqueue("job-1", 3, {}));  // never retried again
}

// Failures reported by workers (not expired leases) requeue the task under
// its own job and give it up on the third. Fail once passed the key stored
// in the lease it erased, and used it afterwards (a server crashed on it); a
// job id longer than the short-string buffer puts that key's text on the
// heap, where a dangling use is likelier to show.
TEST(Scheduler, FailuresReportedByWorkersRequeueUnderTheJobAndGiveUpOnTheThird) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  const std::string job = "job-with-a-name-longer-than-fifteen-characters";
  scheduler.Enqueue(job, 3, {0.25});
  const std::string a = scheduler.RegisterWorker("a", 1);
  const std::string b = scheduler.RegisterWorker("b", 1);
  const std::string c = scheduler.RegisterWorker("c", 1);
  absl::StatusOr<std::optional<FinishedTask>> failed;
  for (const std::string& worker : {a, b, c}) {
    auto tasks = scheduler.Acquire(worker, 1);
    ASSERT_TRUE(tasks.ok());
    ASSERT_EQ(tasks->size(), 1u) << worker;
    EXPECT_EQ(tasks->front().job_id, job);
    failed = scheduler.Fail(worker, tasks->front().task_id, "cannot load the study");
    ASSERT_TRUE(failed.ok()) << failed.status();
  }
  ASSERT_TRUE(failed->has_value());
  EXPECT_EQ((*failed)->job_id, job);
  EXPECT_EQ((*failed)->request_id, 3);
  EXPECT_EQ(scheduler.QueuedCount(), 0);
  EXPECT_EQ(scheduler.LeasedCount(), 0);
  EXPECT_FALSE(scheduler.Enqueue(job, 3, {}));  // never retried again
}

TEST(Scheduler, LateResultIsTakenIfNoOtherAttemptFinished) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  scheduler.Enqueue("job-1", 0, {});
  const std::string slow = scheduler.RegisterWorker("slow", 1);
  const std::string fast = scheduler.RegisterWorker("fast", 1);
  auto first = scheduler.Acquire(slow, 1);
  clock.Advance(kLeaseMs);
  scheduler.ExpireLeases();
  auto second = scheduler.Acquire(fast, 1);
  ASSERT_EQ(second->size(), 1u);
  auto done = scheduler.Complete(slow, first->front().task_id);
  ASSERT_TRUE(done.ok()) << done.status();
  EXPECT_EQ(done->worker_id, slow);
  // The second attempt is now unwanted: its result is refused and its
  // worker is told to stop.
  EXPECT_EQ(scheduler.Complete(fast, second->front().task_id).status().code(), absl::StatusCode::kNotFound);
  HeartbeatReply reply = scheduler.Heartbeat(fast, {second->front().task_id});
  ASSERT_EQ(reply.cancelled_task_ids.size(), 1u);
}

TEST(Scheduler, OnlyAWorkerThatHoldsOrHeldALeaseOfATaskMayCompleteIt) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  scheduler.Enqueue("job-1", 0, {});
  const std::string holder = scheduler.RegisterWorker("holder", 1);
  const std::string other = scheduler.RegisterWorker("other", 1);
  auto leased = scheduler.Acquire(holder, 1);
  ASSERT_EQ(leased->size(), 1u);
  const std::string task = leased->front().task_id;
  // Another registered worker, and one naming the holder's public id only.
  for (const std::string& impostor : {other, PublicWorkerId(holder), std::string("w-1")}) {
    absl::StatusOr<FinishedTask> refused = scheduler.Complete(impostor, task);
    EXPECT_EQ(refused.status().code(), absl::StatusCode::kPermissionDenied) << impostor;
  }
  EXPECT_EQ(scheduler.LeasedCount(), 1) << "a refused result leaves the lease as it was";
  // Queued again after the lease expired, it is still the holder's to answer.
  clock.Advance(kLeaseMs);
  scheduler.ExpireLeases();
  EXPECT_EQ(scheduler.Complete(other, task).status().code(), absl::StatusCode::kPermissionDenied);
  absl::StatusOr<FinishedTask> done = scheduler.Complete(holder, task);
  ASSERT_TRUE(done.ok()) << done.status();
  EXPECT_EQ(done->worker_id, holder);
}

TEST(Scheduler, WorkerIdsCarryASecretPartThatIsNeverShown) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  const std::string first = scheduler.RegisterWorker("a", 1);
  const std::string second = scheduler.RegisterWorker("b", 1);
  EXPECT_EQ(PublicWorkerId(first), "w-1");
  EXPECT_EQ(PublicWorkerId(second), "w-2");
  // "w-<n>." and 16 hex digits of 64 random bits.
  EXPECT_EQ(first.size(), std::string("w-1.").size() + 16);
  EXPECT_NE(first.substr(4), second.substr(4));
  EXPECT_EQ(PublicWorkerId("w-7"), "w-7");
}

TEST(Scheduler, UnknownTaskAndUnknownWorkerAreNotFound) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  const std::string worker = scheduler.RegisterWorker("w", 1);
  EXPECT_EQ(scheduler.Complete(worker, "garbage").status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(scheduler.Complete(worker, "job-1/x/1").status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(scheduler.Acquire("w-42", 1).status().code(), absl::StatusCode::kNotFound);
}

TEST(Scheduler, DroppedJobLosesItsTasksAndOthersContinue) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  scheduler.Enqueue("job-1", 0, {});
  scheduler.Enqueue("job-1", 1, {});
  scheduler.Enqueue("job-2", 0, {});
  const std::string worker = scheduler.RegisterWorker("w", 1);
  auto leased = scheduler.Acquire(worker, 1);
  ASSERT_EQ(leased->front().job_id, "job-1");
  scheduler.DropJob("job-1");
  EXPECT_EQ(scheduler.Complete(worker, leased->front().task_id).status().code(), absl::StatusCode::kNotFound);
  auto rest = scheduler.Acquire(worker, 10);
  ASSERT_EQ(rest->size(), 1u);
  EXPECT_EQ(rest->front().job_id, "job-2");
}

TEST(Scheduler, LongPollWakesWhenATaskIsQueued) {
  FakeClock clock;
  Scheduler scheduler(&clock, Options());
  const std::string worker = scheduler.RegisterWorker("w", 1);
  // Generous: the guard only matters if the wake-up is broken.
  constexpr std::int64_t kFailureGuardMs = 60'000;
  std::vector<Task> got;
  std::thread poller([&] { got = *scheduler.AcquireWait(worker, 1, kFailureGuardMs); });
  scheduler.Enqueue("job-1", 0, {});
  poller.join();
  // Either the poll started before the enqueue and was woken, or after and
  // found the task at once: both end with the task, never a timeout.
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].job_id, "job-1");
}

// Shutdown() must wake a long poll that is already blocked in its wait (the
// scheduler's hook says when it is), not only refuse later ones: the poll
// returns, empty, long before its own wait would end.
TEST(Scheduler, ShutdownEndsLongPolls) {
  FakeClock clock;
  SchedulerOptions options = Options();
  std::promise<void> blocked;
  std::once_flag blocked_once;
  options.on_long_poll_blocks = [&] { std::call_once(blocked_once, [&] { blocked.set_value(); }); };
  Scheduler scheduler(&clock, options);
  const std::string worker = scheduler.RegisterWorker("w", 1);
  // Only a wake-up can end this poll within the test: its own wait is far
  // longer than the guard. The guard bounds how long a broken wake-up is
  // waited for; a working one takes microseconds.
  constexpr std::int64_t kPollMs = 600'000;
  constexpr auto kFailureGuard = std::chrono::seconds(20);
  std::promise<absl::StatusOr<std::vector<Task>>> polled;
  std::future<absl::StatusOr<std::vector<Task>>> poll_result = polled.get_future();
  std::thread poller([&] { polled.set_value(scheduler.AcquireWait(worker, 1, kPollMs)); });

  const bool poll_blocked = blocked.get_future().wait_for(kFailureGuard) == std::future_status::ready;
  scheduler.Shutdown();
  const bool poll_returned = poll_result.wait_for(kFailureGuard) == std::future_status::ready;
  // A poll that Shutdown() did not wake is woken by a task instead, so that
  // the test can end and report it.
  if (!poll_returned) scheduler.Enqueue("job-1", 0, {});
  poller.join();

  EXPECT_TRUE(poll_blocked) << "AcquireWait never blocked: Shutdown() was not tested on a waiting poll";
  ASSERT_TRUE(poll_returned) << "a blocked long poll was still waiting 20 s after Shutdown()";
  const absl::StatusOr<std::vector<Task>> tasks = poll_result.get();
  ASSERT_TRUE(tasks.ok()) << tasks.status();
  EXPECT_TRUE(tasks->empty());
  // And a poll after Shutdown() does not wait at all.
  auto late = scheduler.AcquireWait(worker, 1, kPollMs);
  ASSERT_TRUE(late.ok()) << late.status();
  EXPECT_TRUE(late->empty());
}

TEST(SchedulerOptions, HeartbeatMustBeShorterThanLease) {
  SchedulerOptions options;
  options.lease_ms = 100;
  options.heartbeat_interval_ms = 100;
  EXPECT_EQ(options.Validate().code(), absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace mbopt::scheduler
