#include "server/scheduler/scheduler.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <random>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace mbopt::scheduler {
namespace {

// Separates a worker id's public part from its secret one.
constexpr char kSecretSeparator[] = ".";

// 64 bits from the system's random source (getrandom on Linux), in hex.
std::string RandomHex64() {
  std::random_device device;
  const std::uint64_t bits = (std::uint64_t{device()} << 32) ^ device();
  return absl::StrCat(absl::Hex(bits, absl::kZeroPad16));
}

}  // namespace

std::string PublicWorkerId(std::string_view worker_id) {
  return std::string(worker_id.substr(0, worker_id.find(kSecretSeparator)));
}

absl::Status SchedulerOptions::Validate() const {
  if (lease_ms <= 0) return absl::InvalidArgumentError(absl::StrCat("lease_ms must be > 0, got ", lease_ms));
  if (heartbeat_interval_ms <= 0 || heartbeat_interval_ms >= lease_ms) {
    return absl::InvalidArgumentError(absl::StrCat("heartbeat interval must be > 0 and below the lease (",
                                                   lease_ms, " ms), got ", heartbeat_interval_ms, " ms"));
  }
  if (max_attempts < 1) {
    return absl::InvalidArgumentError(absl::StrCat("max_attempts must be >= 1, got ", max_attempts));
  }
  return absl::OkStatus();
}

Scheduler::Scheduler(const Clock* clock, SchedulerOptions options)
    : clock_(clock), options_(std::move(options)) {}

bool TaskNeeds::RunnableBy(const WorkerCapabilities& capabilities) const {
  if (loads_fmus && capabilities.fmu_platform.empty()) return false;
  if (loads_fmus && !fmu_platforms.empty() &&
      std::find(fmu_platforms.begin(), fmu_platforms.end(), capabilities.fmu_platform) == fmu_platforms.end()) {
    return false;
  }
  return driver.empty() ||
         std::find(capabilities.drivers.begin(), capabilities.drivers.end(), driver) != capabilities.drivers.end();
}

std::string TaskNeeds::Describe() const {
  if (!driver.empty()) return absl::StrCat("driver \"", driver, "\"");
  if (!loads_fmus) return "";
  if (fmu_platforms.empty()) return "FMU support (a platform it loads FMUs for)";
  return absl::StrCat("FMU support for ", absl::StrJoin(fmu_platforms, " or "),
                      " (the platforms the FMU has binaries for)");
}

std::string Scheduler::RegisterWorker(const std::string& name, int slots, WorkerCapabilities capabilities,
                                      const std::string& holder) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::int64_t number = next_worker_++;
  std::string id = absl::StrCat("w-", number, kSecretSeparator, RandomHex64());
  Worker& worker = workers_[id];
  worker.name = name;
  worker.holder = holder;
  worker.slots = std::max(1, slots);
  worker.last_seen_ms = clock_->NowMs();
  worker.capabilities = std::move(capabilities);
  worker.number = number;
  return id;
}

std::vector<std::string> Scheduler::WorkerIdsHeldBy(const std::string& holder) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> ids;
  for (const auto& [id, worker] : workers_) {
    if (worker.holder == holder) ids.push_back(id);
  }
  return ids;
}

void Scheduler::SetJobNeeds(const std::string& job_id, TaskNeeds needs) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (needs.driver.empty() && !needs.loads_fmus) {
      job_needs_.erase(job_id);
    } else {
      job_needs_[job_id] = std::move(needs);
    }
  }
  task_available_.notify_all();
}

bool Scheduler::SomeWorkerCan(const TaskNeeds& needs) const {
  // Built-in scenes need no particular worker, and none registered yet is
  // no reason to refuse them: every worker runs them.
  if (needs.driver.empty() && !needs.loads_fmus) return true;
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [id, worker] : workers_) {
    if (needs.RunnableBy(worker.capabilities)) return true;
  }
  return false;
}

std::vector<std::string> Scheduler::OfferedDrivers() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::set<std::string> drivers;
  for (const auto& [id, worker] : workers_) drivers.insert(worker.capabilities.drivers.begin(), worker.capabilities.drivers.end());
  return {drivers.begin(), drivers.end()};
}

std::vector<WorkerView> Scheduler::Workers() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::map<std::string, int> held;
  for (const auto& [task_id, key] : leases_) ++held[entries_.at(key).worker_id];
  std::vector<std::pair<std::int64_t, WorkerView>> numbered;
  const std::int64_t now = clock_->NowMs();
  for (const auto& [id, worker] : workers_) {
    WorkerView view;
    view.public_id = PublicWorkerId(id);
    view.name = worker.name;
    view.holder = worker.holder;
    view.slots = worker.slots;
    view.capabilities = worker.capabilities;
    view.analyses_done = worker.analyses_done;
    view.tasks_held = held.count(id) != 0 ? held.at(id) : 0;
    view.silent_ms = std::max<std::int64_t>(0, now - worker.last_seen_ms);
    view.quarantined = worker.quarantined;
    numbered.emplace_back(worker.number, std::move(view));
  }
  std::sort(numbered.begin(), numbered.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<WorkerView> out;
  for (auto& [number, view] : numbered) out.push_back(std::move(view));
  return out;
}

bool Scheduler::Enqueue(const std::string& job_id, std::int64_t request_id, std::vector<double> x_scaled,
                        bool want_gradients) {
  std::vector<NewTask> one;
  one.push_back(NewTask{request_id, std::move(x_scaled), want_gradients});
  return EnqueueAll(job_id, std::move(one)) == 1;
}

int Scheduler::EnqueueAll(const std::string& job_id, std::vector<NewTask> tasks) {
  int queued = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    for (NewTask& task : tasks) {
      const Key key{job_id, task.request_id};
      if (entries_.count(key) != 0 || finished_.count(key) != 0) continue;
      Entry& entry = entries_[key];
      entry.job_id = job_id;
      entry.request_id = task.request_id;
      entry.x_scaled = std::move(task.x_scaled);
      entry.want_gradients = task.want_gradients;
      entry.queued_at = now;
      queues_[job_id].push_back(task.request_id);
      ++queued;
    }
  }
  if (queued > 0) task_available_.notify_all();
  return queued;
}

bool Scheduler::HasOtherLiveWorker(const std::string& worker_id, const std::set<std::string>& excluded) const {
  const std::int64_t silence = options_.worker_silence_ms > 0 ? options_.worker_silence_ms : 3 * options_.lease_ms;
  const std::int64_t now = clock_->NowMs();
  for (const auto& [id, worker] : workers_) {
    if (id == worker_id || excluded.count(id) != 0) continue;
    if (now - worker.last_seen_ms <= silence) return true;
  }
  return false;
}

int Scheduler::FairShareLocked(const std::string& worker_id) const {
  std::int64_t total_slots = 0;
  for (const auto& [id, worker] : workers_) total_slots += worker.slots;
  std::int64_t queued = 0;
  for (const auto& [job_id, queue] : queues_) queued += static_cast<std::int64_t>(queue.size());
  std::int64_t leased_to_worker = 0;
  for (const auto& [task_id, key] : leases_) {
    if (entries_.at(key).worker_id == worker_id) ++leased_to_worker;
  }
  const std::int64_t slots = workers_.at(worker_id).slots;
  const std::int64_t outstanding = queued + static_cast<std::int64_t>(leases_.size());
  const std::int64_t share = (outstanding * slots + total_slots - 1) / std::max<std::int64_t>(1, total_slots);
  return static_cast<int>(std::max(share, slots) - leased_to_worker);
}

std::vector<Task> Scheduler::AcquireLocked(const std::string& worker_id, int max_tasks) {
  std::vector<Task> tasks;
  if (workers_.at(worker_id).quarantined) return tasks;
  if (max_tasks > 1) max_tasks = std::min(max_tasks, FairShareLocked(worker_id));
  const std::int64_t now = clock_->NowMs();
  while (static_cast<int>(tasks.size()) < max_tasks && !queues_.empty()) {
    // Round robin: the first job after the last one served, wrapping around,
    // that has a task this worker may take.
    auto start = queues_.upper_bound(last_served_job_);
    bool found = false;
    for (size_t step = 0; step < queues_.size() && !found; ++step) {
      if (start == queues_.end()) start = queues_.begin();
      auto& [job_id, queue] = *start;
      // A job whose tasks this worker cannot run is passed over whole.
      const auto needs = job_needs_.find(job_id);
      const bool runnable =
          needs == job_needs_.end() || needs->second.RunnableBy(workers_.at(worker_id).capabilities);
      for (auto it = queue.begin(); runnable && it != queue.end(); ++it) {
        Entry& entry = entries_.at(Key{job_id, *it});
        // A spot check's second opinion comes from another worker, always.
        if (entry.answered_workers.count(worker_id) != 0) continue;
        // A retry goes to a worker that has not failed it yet, if one is around.
        if (entry.failed_workers.count(worker_id) != 0 && HasOtherLiveWorker(worker_id, entry.failed_workers)) {
          continue;
        }
        entry.leased = true;
        entry.attempts += 1;
        entry.worker_id = worker_id;
        entry.task_id = absl::StrCat(job_id, "/", entry.request_id, "/", entry.attempts);
        entry.lease_deadline_ms = now + options_.lease_ms;
        leases_[entry.task_id] = Key{job_id, entry.request_id};
        tasks.push_back(Task{entry.task_id, job_id, entry.request_id, entry.x_scaled, entry.attempts,
                             entry.lease_deadline_ms, entry.want_gradients});
        queue.erase(it);
        last_served_job_ = job_id;
        found = true;
        break;
      }
      if (found && queue.empty()) {
        queues_.erase(start);
      } else if (!found) {
        ++start;
      }
    }
    if (!found) break;
  }
  return tasks;
}

absl::StatusOr<std::vector<Task>> Scheduler::Acquire(const std::string& worker_id, int max_tasks) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto worker = workers_.find(worker_id);
  if (worker == workers_.end()) {
    return absl::NotFoundError(absl::StrCat("unknown worker '", worker_id, "'; register again"));
  }
  worker->second.last_seen_ms = clock_->NowMs();
  return AcquireLocked(worker_id, std::max(1, max_tasks));
}

absl::StatusOr<std::vector<Task>> Scheduler::AcquireWait(const std::string& worker_id, int max_tasks,
                                                         std::int64_t wait_ms) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(std::max<std::int64_t>(0, wait_ms));
  std::unique_lock<std::mutex> lock(mutex_);
  while (true) {
    auto worker = workers_.find(worker_id);
    if (worker == workers_.end()) {
      return absl::NotFoundError(absl::StrCat("unknown worker '", worker_id, "'; register again"));
    }
    worker->second.last_seen_ms = clock_->NowMs();
    std::vector<Task> tasks = AcquireLocked(worker_id, std::max(1, max_tasks));
    if (!tasks.empty() || shutdown_) return tasks;
    if (options_.on_long_poll_blocks) options_.on_long_poll_blocks();
    if (task_available_.wait_until(lock, deadline) == std::cv_status::timeout) {
      return AcquireLocked(worker_id, std::max(1, max_tasks));
    }
  }
}

void Scheduler::RemoveFromQueue(const Key& key) {
  auto queue = queues_.find(key.first);
  if (queue == queues_.end()) return;
  auto& ids = queue->second;
  ids.erase(std::remove(ids.begin(), ids.end(), key.second), ids.end());
  if (ids.empty()) queues_.erase(queue);
}

absl::StatusOr<std::map<Scheduler::Key, Scheduler::Entry>::iterator> Scheduler::AnswerableLocked(
    const std::string& worker_id, const std::string& task_id) {
  // The task id names its analysis; an older attempt's id is still good.
  const size_t slash2 = task_id.rfind('/');
  const size_t slash1 = slash2 == std::string::npos || slash2 == 0 ? std::string::npos : task_id.rfind('/', slash2 - 1);
  std::int64_t request_id = -1;
  if (slash1 != std::string::npos &&
      !absl::SimpleAtoi(task_id.substr(slash1 + 1, slash2 - slash1 - 1), &request_id)) {
    request_id = -1;
  }
  const Key key{slash1 == std::string::npos ? std::string() : task_id.substr(0, slash1), request_id};
  auto entry = entries_.find(key);
  if (request_id < 0 || entry == entries_.end() || entry->second.attempts == 0 ||
      entry->second.answered_workers.count(worker_id) != 0) {
    return absl::NotFoundError(absl::StrCat("task '", task_id, "' is not outstanding (unknown, finished, "
                                                               "given up, or its job ended)"));
  }
  // Only a worker that holds or held a lease of this analysis may answer
  // it: without this any holder of a worker token could answer every
  // user's analyses with values of its choosing.
  const Entry& wanted = entry->second;
  if (!(wanted.leased && wanted.worker_id == worker_id) && wanted.failed_workers.count(worker_id) == 0) {
    return absl::PermissionDeniedError(absl::StrCat("task '", task_id, "' was never leased to worker ",
                                                    PublicWorkerId(worker_id), "; its result is refused"));
  }
  auto worker = workers_.find(worker_id);
  if (worker != workers_.end() && worker->second.quarantined) {
    return absl::PermissionDeniedError(absl::StrCat("worker ", PublicWorkerId(worker_id),
                                                    " is quarantined (a spot check caught a wrong result); its "
                                                    "result of task '", task_id, "' is refused"));
  }
  return entry;
}

absl::StatusOr<FinishedTask> Scheduler::Complete(const std::string& worker_id, const std::string& task_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  auto worker = workers_.find(worker_id);
  if (worker != workers_.end()) worker->second.last_seen_ms = clock_->NowMs();
  absl::StatusOr<std::map<Key, Entry>::iterator> found = AnswerableLocked(worker_id, task_id);
  if (!found.ok()) return found.status();
  auto entry = *found;
  const Key key = entry->first;
  FinishedTask done{entry->second.job_id, entry->second.request_id, std::move(entry->second.x_scaled),
                    entry->second.attempts, worker_id, ""};
  done.latency_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - entry->second.queued_at).count();
  if (entry->second.leased) {
    leases_.erase(entry->second.task_id);
  } else {
    RemoveFromQueue(key);
  }
  entries_.erase(entry);
  finished_.insert(key);
  if (worker != workers_.end()) ++worker->second.analyses_done;
  return done;
}

absl::Status Scheduler::AskAnotherWorker(const std::string& worker_id, const std::string& task_id) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto worker = workers_.find(worker_id);
    if (worker != workers_.end()) worker->second.last_seen_ms = clock_->NowMs();
    absl::StatusOr<std::map<Key, Entry>::iterator> found = AnswerableLocked(worker_id, task_id);
    if (!found.ok()) return found.status();
    Entry& entry = (*found)->second;
    const Key key = (*found)->first;
    if (entry.leased) {
      leases_.erase(entry.task_id);
      entry.leased = false;
    } else {
      RemoveFromQueue(key);
    }
    entry.answered_workers.insert(worker_id);
    queues_[key.first].push_front(key.second);
    if (worker != workers_.end()) ++worker->second.analyses_done;
  }
  task_available_.notify_all();
  return absl::OkStatus();
}

bool Scheduler::HasLiveWorkerBesides(const std::set<std::string>& worker_ids) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::set<std::string> excluded = worker_ids;
  for (const auto& [id, worker] : workers_) {
    if (worker.quarantined) excluded.insert(id);
  }
  return HasOtherLiveWorker("", excluded);
}

std::optional<std::vector<FinishedTask>> Scheduler::Quarantine(const std::string& worker_id) {
  std::vector<FinishedTask> given_up;
  bool requeued = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto worker = workers_.find(worker_id);
    if (worker == workers_.end() || worker->second.quarantined) return std::nullopt;
    worker->second.quarantined = true;
    given_up = FailLeasesLocked(
        [&worker_id](const Entry& e) { return e.worker_id == worker_id; },
        [&](const Entry& e) {
          return absl::StrCat("worker ", PublicWorkerId(worker_id), " was quarantined holding task ", e.task_id);
        },
        &requeued);
  }
  if (requeued) task_available_.notify_all();
  return given_up;
}

std::optional<FinishedTask> Scheduler::FailLocked(Key key, const std::string& reason) {
  Entry& entry = entries_.at(key);
  leases_.erase(entry.task_id);
  entry.leased = false;
  entry.failures += 1;
  entry.failed_workers.insert(entry.worker_id);
  entry.last_failure = reason;
  if (entry.failures >= options_.max_attempts) {
    FinishedTask given_up{entry.job_id, entry.request_id, std::move(entry.x_scaled), entry.attempts, "",
                          absl::StrCat("gave up after ", entry.failures, " failed attempts; last: ", reason)};
    entries_.erase(key);
    finished_.insert(key);
    return given_up;
  }
  queues_[key.first].push_front(key.second);
  return std::nullopt;
}

absl::StatusOr<std::optional<FinishedTask>> Scheduler::Fail(const std::string& worker_id,
                                                            const std::string& task_id,
                                                            const std::string& reason) {
  std::optional<FinishedTask> result;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto lease = leases_.find(task_id);
    if (lease == leases_.end() || entries_.at(lease->second).worker_id != worker_id) {
      return absl::NotFoundError(absl::StrCat("task '", task_id, "' is not leased to worker '", worker_id, "'"));
    }
    result = FailLocked(lease->second, absl::StrCat("worker ", PublicWorkerId(worker_id), ": ", reason));
  }
  if (!result) task_available_.notify_all();
  return result;
}

HeartbeatReply Scheduler::Heartbeat(const std::string& worker_id, const std::vector<std::string>& task_ids) {
  std::lock_guard<std::mutex> lock(mutex_);
  HeartbeatReply reply;
  auto worker = workers_.find(worker_id);
  if (worker == workers_.end()) return reply;
  reply.known = true;
  const std::int64_t now = clock_->NowMs();
  worker->second.last_seen_ms = now;
  for (const std::string& task_id : task_ids) {
    auto lease = leases_.find(task_id);
    if (lease == leases_.end()) {
      reply.cancelled_task_ids.push_back(task_id);
      continue;
    }
    Entry& entry = entries_.at(lease->second);
    if (entry.worker_id != worker_id) {
      reply.cancelled_task_ids.push_back(task_id);
      continue;
    }
    entry.lease_deadline_ms = now + options_.lease_ms;
  }
  return reply;
}

std::vector<FinishedTask> Scheduler::FailLeasesLocked(const std::function<bool(const Entry&)>& lost,
                                                     const std::function<std::string(const Entry&)>& reason,
                                                     bool* requeued) {
  std::vector<Key> keys;
  for (const auto& [task_id, key] : leases_) {
    if (lost(entries_.at(key))) keys.push_back(key);
  }
  std::vector<FinishedTask> given_up;
  for (const Key& key : keys) {
    std::optional<FinishedTask> done = FailLocked(key, reason(entries_.at(key)));
    if (done) {
      given_up.push_back(std::move(*done));
    } else {
      *requeued = true;
    }
  }
  return given_up;
}

std::vector<FinishedTask> Scheduler::ExpireLeases() {
  std::vector<FinishedTask> given_up;
  bool requeued = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::int64_t now = clock_->NowMs();
    given_up = FailLeasesLocked(
        [now](const Entry& e) { return e.lease_deadline_ms <= now; },
        [](const Entry& e) { return absl::StrCat("lease of task ", e.task_id, " on worker ", PublicWorkerId(e.worker_id), " expired");
        },
        &requeued);
  }
  if (requeued) task_available_.notify_all();
  return given_up;
}

std::vector<FinishedTask> Scheduler::WorkerLost(const std::string& worker_id) {
  std::vector<FinishedTask> given_up;
  bool requeued = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto worker = workers_.find(worker_id);
    if (worker == workers_.end()) return given_up;
    const std::string name = worker->second.name;
    workers_.erase(worker);
    given_up = FailLeasesLocked(
        [&worker_id](const Entry& e) { return e.worker_id == worker_id; },
        [&](const Entry& e) {
          return absl::StrCat("worker ", PublicWorkerId(worker_id), " (", name, ") disconnected with task ", e.task_id);
        },
        &requeued);
  }
  if (requeued) task_available_.notify_all();
  return given_up;
}

bool Scheduler::IsKnownWorker(const std::string& worker_id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return workers_.count(worker_id) > 0;
}

bool Scheduler::WaitForShutdown(std::int64_t wait_ms) const {
  std::unique_lock<std::mutex> lock(mutex_);
  return shutdown_signal_.wait_for(lock, std::chrono::milliseconds(wait_ms), [this] { return shutdown_; });
}

void Scheduler::DropJob(const std::string& job_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  queues_.erase(job_id);
  job_needs_.erase(job_id);
  for (auto it = entries_.lower_bound(Key{job_id, INT64_MIN}); it != entries_.end() && it->first.first == job_id;) {
    if (it->second.leased) leases_.erase(it->second.task_id);
    it = entries_.erase(it);
  }
  for (auto it = finished_.lower_bound(Key{job_id, INT64_MIN}); it != finished_.end() && it->first == job_id;) {
    it = finished_.erase(it);
  }
}

void Scheduler::Shutdown() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    shutdown_ = true;
  }
  task_available_.notify_all();
  shutdown_signal_.notify_all();
}

int Scheduler::QueuedCount() const {
  std::lock_guard<std::mutex> lock(mutex_);
  int count = 0;
  for (const auto& [job, queue] : queues_) count += static_cast<int>(queue.size());
  return count;
}

int Scheduler::LeasedCount() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(leases_.size());
}

}  // namespace mbopt::scheduler
