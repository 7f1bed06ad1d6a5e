#include "worker/service/worker_service.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "absl/strings/str_cat.h"
#include "common/monotonic_clock.h"
#include "common/secure_channel/connection_diagnosis.h"
#include "mbopt/v1/service.grpc.pb.h"
#include "worker/budget/analysis_budget.h"
#include "worker/fmu/fmu.h"
#include "worker/service/batch_log_line.h"
#include "worker/service/result_size.h"
#include "worker/service/task_evaluator.h"

namespace mbopt::worker {
namespace {

using Clock = std::chrono::system_clock;

constexpr int kDefaultHeartbeatMs = 1000;
// The longest the acquiring thread waits for the server to confirm Attach.
constexpr auto kAttachWait = std::chrono::seconds(5);
constexpr auto kShortCallDeadline = std::chrono::seconds(10);
// How long a finished result is retried while the server is unreachable; past
// that its lease has long expired and the task runs elsewhere.
constexpr auto kReportRetryWindow = std::chrono::seconds(60);
constexpr size_t kMaxCachedStudies = 64;
// The most bytes of results held for one call while the server's message
// limit is not known.
constexpr std::int64_t kDefaultBatchBytes = 2 * 1024 * 1024;
// How long finished results wait for others. Only the results of cheap
// analyses (shorter than kCheapAnalysis) are held, and no longer than
// kMaxHold (checked as each analysis ends), so a held result waits at most
// about kMaxHold + kCheapAnalysis and a longer analysis is reported as soon
// as it ends: no result is kept from the job's log (and from a crash-safe
// place) for long.
constexpr auto kMaxHold = std::chrono::seconds(1);
constexpr auto kCheapAnalysis = std::chrono::milliseconds(100);

std::string DefaultName() {
  char host[256] = {0};
  if (gethostname(host, sizeof host - 1) != 0) std::snprintf(host, sizeof host, "worker");
  return absl::StrCat(host, ":", getpid());
}

bool Retryable(const grpc::Status& s) {
  return s.error_code() == grpc::StatusCode::UNAVAILABLE ||
         s.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED ||
         s.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED;
}

// Blocking calls in progress; cancelled all at once when the worker stops.
class CallRegistry {
 public:
  void Add(grpc::ClientContext* context) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (cancelled_) context->TryCancel();
    active_.insert(context);
  }
  void Remove(grpc::ClientContext* context) {
    std::lock_guard<std::mutex> lock(mutex_);
    active_.erase(context);
  }
  void CancelAll() {
    std::lock_guard<std::mutex> lock(mutex_);
    cancelled_ = true;
    for (auto* c : active_) c->TryCancel();
  }

 private:
  std::mutex mutex_;
  std::set<grpc::ClientContext*> active_;
  bool cancelled_ = false;
};

class ScopedCall {
 public:
  ScopedCall(CallRegistry& registry, grpc::ClientContext* context)
      : registry_(registry), context_(context) {
    registry_.Add(context_);
  }
  ~ScopedCall() { registry_.Remove(context_); }

 private:
  CallRegistry& registry_;
  grpc::ClientContext* context_;
};

struct QueuedTask {
  v1::AnalysisTask task;
  std::string worker_id;  // the registration it was acquired under
};

class Worker : public std::enable_shared_from_this<Worker> {
 public:
  Worker(const WorkerOptions& options, StopSignal& stop)
      : options_(options),
        stop_(stop),
        backoff_seed_(static_cast<std::uint64_t>(
                          std::chrono::steady_clock::now().time_since_epoch().count()) ^
                      static_cast<std::uint64_t>(getpid())) {
    if (options_.name.empty()) options_.name = DefaultName();
    grpc::ChannelArguments args;
    args.SetMaxReceiveMessageSize(256 * 1024 * 1024);
    stub_ = v1::WorkerService::NewStub(secure_channel::CreateChannel(options_.server_address, options_.security, args));
  }

  void Run() {
    std::weak_ptr<Worker> weak = weak_from_this();
    stop_.OnStop([weak] {
      if (auto self = weak.lock()) self->HandleStop();
    });
    std::vector<std::thread> threads;
    for (int i = 0; i < options_.slots; ++i) threads.emplace_back([this] { SlotLoop(); });
    threads.emplace_back([this] { HeartbeatLoop(); });
    threads.emplace_back([this] { PresenceLoop(); });
    AcquireLoop();
    HandleStop();
    for (auto& t : threads) t.join();
    Log(absl::StrCat("stopped after ", tasks_received_, " tasks"));
  }

  // The most tasks in hand when asking for more (WorkerOptions::batch).
  int Capacity() const { return std::max(options_.slots, std::min(options_.batch, kMaxBatch)); }

  // Why the worker stopped on its own (Denied, Fatal); OK otherwise.
  absl::Status fatal() {
    std::lock_guard<std::mutex> lock(mutex_);
    return fatal_;
  }

 private:

  // A refusal of the token (missing, wrong, revoked, not a worker's) stops
  // the worker: retrying cannot help. Returns whether `status` is one.
  bool Denied(const grpc::Status& status) {
    if (status.error_code() != grpc::StatusCode::UNAUTHENTICATED &&
        status.error_code() != grpc::StatusCode::PERMISSION_DENIED) {
      return false;
    }
    Fatal(absl::StrCat("server at ", options_.server_address, " refused this worker: ", status.error_message()));
    return true;
  }

  void Fatal(const std::string& message) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!fatal_.ok()) return;
      fatal_ = absl::PermissionDeniedError(message);
    }
    stop_.Stop();
  }

  void Log(const std::string& message) {
    std::fprintf(stderr, "mbopt-worker %s: %s\n", options_.name.c_str(), message.c_str());
  }

  void HandleStop() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    cv_.notify_all();
    calls_.CancelAll();
  }

  bool Register() {
    v1::RegisterWorkerRequest request;
    request.set_name(options_.name);
    request.set_slots(options_.slots);
    // What it can run, so the server hands it only tasks it can run.
    request.set_fmu_platform(fmu::ThisPlatform());
    if (options_.external != nullptr) {
      for (const external::DriverDeclaration& driver : options_.external->drivers) request.add_drivers(driver.name);
    }
    v1::RegisterWorkerResponse response;
    grpc::ClientContext context;
    context.set_deadline(Clock::now() + kShortCallDeadline);
    ScopedCall scoped(calls_, &context);
    grpc::Status status = stub_->Register(&context, request, &response);
    if (!status.ok()) {
      if (Denied(status)) return false;
      if (!ever_registered_ && status.error_code() == grpc::StatusCode::UNAVAILABLE && !stop_.stopped()) {
        const std::string cause = secure_channel::DiagnoseConnectionFailure(options_.server_address, options_.security);
        if (!cause.empty()) {
          Fatal(absl::StrCat("cannot connect to server at ", options_.server_address, ": ", cause));
          return false;
        }
      }
      if (!unreachable_logged_ && !stop_.stopped()) {
        Log(absl::StrCat("cannot reach server at ", options_.server_address, ": ",
                         status.error_message(), "; retrying"));
        unreachable_logged_ = true;
      }
      return false;
    }
    unreachable_logged_ = false;
    ever_registered_ = true;
    std::lock_guard<std::mutex> lock(mutex_);
    worker_id_ = response.worker_id();
    heartbeat_ms_ = response.heartbeat_interval_ms() > 0 ? response.heartbeat_interval_ms()
                                                         : kDefaultHeartbeatMs;
    max_message_bytes_ = response.max_message_bytes();
    max_result_bytes_ = response.max_result_bytes();
    takes_packed_values_ = response.takes_packed_values();
    registered_ = true;
    Log(absl::StrCat("registered with ", options_.server_address, " as ", worker_id_, " (",
                     options_.slots, " slots)"));
    cv_.notify_all();  // the presence thread attaches this registration
    return true;
  }

  void AcquireLoop() {
    Backoff backoff(options_.backoff, backoff_seed_);
    while (!stop_.stopped()) {
      bool registered;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        registered = registered_;
      }
      if (!registered) {
        if (!Register()) {
          if (stop_.WaitFor(backoff.Next())) break;
          continue;
        }
        backoff.Reset();
      }
      {
        // Tasks only once the server would notice this process die (or
        // once it turned out that it cannot: then the lease is the backstop).
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait_for(lock, kAttachWait, [this] { return stopping_ || !registered_ || attach_settled_ == worker_id_; });
        if (stopping_) break;
        if (!registered_) continue;
      }
      int free_slots;
      std::string worker_id;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [this] { return stopping_ || busy_ < options_.slots; });
        if (stopping_) break;
        free_slots = Capacity() - busy_;
        worker_id = worker_id_;
      }
      v1::AcquireTasksRequest request;
      request.set_worker_id(worker_id);
      request.set_max_tasks(free_slots);
      request.set_wait_ms(options_.acquire_wait_ms);
      v1::AcquireTasksResponse response;
      grpc::ClientContext context;
      context.set_deadline(Clock::now() + std::chrono::milliseconds(options_.acquire_wait_ms) +
                           kShortCallDeadline);
      grpc::Status status;
      {
        ScopedCall scoped(calls_, &context);
        status = stub_->AcquireTasks(&context, request, &response);
      }
      if (!status.ok()) {
        if (stop_.stopped() || Denied(status)) break;
        if (status.error_code() != grpc::StatusCode::DEADLINE_EXCEEDED) {
          // The server restarted, forgot us, or is gone: register again
          // (which waits for it to come back).
          Log(absl::StrCat("lost the server (", status.error_message(), "); reconnecting"));
          std::lock_guard<std::mutex> lock(mutex_);
          registered_ = false;
        }
        if (stop_.WaitFor(backoff.Next())) break;
        continue;
      }
      backoff.Reset();
      for (const auto& task : response.tasks()) Take(task, worker_id);
    }
  }

  // A task leased to this worker (by AcquireTasks, or with the answer to a
  // result): queued for a slot.
  void Take(const v1::AnalysisTask& task, const std::string& worker_id) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++tasks_received_;
      if (options_.die_after_tasks > 0 && tasks_received_ == options_.die_after_tasks) {
        Log(absl::StrCat("--die-after-tasks ", options_.die_after_tasks, ": killing this process with task ",
                         task.task_id(), " in hand"));
        std::fflush(stderr);
        raise(SIGKILL);
      }
      queue_.push_back({task, worker_id});
      cancelled_[task.task_id()] = false;
      cancel_flags_[task.task_id()] = std::make_shared<std::atomic<bool>>(false);
      ++busy_;
    }
    cv_.notify_all();
  }

  void SlotLoop() {
    while (true) {
      QueuedTask item;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
        // On stop, tasks not yet started are left to their leases; results
        // held for a batch are still delivered.
        if (stopping_) {
          std::vector<v1::TaskResult> held;
          held.swap(held_);
          held_bytes_ = 0;
          lock.unlock();
          if (!held.empty()) Deliver(std::move(held), 0);
          return;
        }
        item = std::move(queue_.front());
        queue_.pop_front();
      }
      const v1::AnalysisTask& task = item.task;
      v1::TaskResult result;
      result.set_worker_id(item.worker_id);
      result.set_task_id(task.task_id());
      result.set_job_id(task.job_id());
      result.set_request_id(task.request_id());
      std::string study_error;
      auto study = StudyFor(task.job_id(), &study_error);
      bool deliver = true;
      std::int64_t max_message_bytes = 0;
      std::int64_t max_result_bytes = 0;
      bool takes_packed_values = false;
      std::shared_ptr<std::atomic<bool>> cancel_flag;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        std::shared_ptr<std::atomic<bool>>& flag = cancel_flags_[task.task_id()];
        if (flag == nullptr) flag = std::make_shared<std::atomic<bool>>(false);
        cancel_flag = flag;
        max_message_bytes = max_message_bytes_;
        max_result_bytes = max_result_bytes_;
        takes_packed_values = takes_packed_values_;
      }
      const auto started = std::chrono::steady_clock::now();
      const std::string cannot_run = study != nullptr ? CannotRun(study->study, options_.external) : "";
      if (!cannot_run.empty()) {
        // Not the design point's fault: another worker may declare the
        // driver (the server prefers one that has not failed the task).
        result.set_ok(false);
        result.set_retry(true);
        result.set_failure_reason(cannot_run);
      } else if (study != nullptr) {
        std::optional<external::ExternalSceneAnalyzer> analyzer;
        if (options_.external != nullptr) analyzer.emplace(*options_.external, task.task_id());
        // The analysis runs on this process' clock and stops when the
        // heartbeat thread raises its task's cancel flag.
        const budget::AnalysisBudget analysis_budget(
            &MonotonicSeconds, [cancel_flag] { return cancel_flag->load(std::memory_order_relaxed); });
        EvaluateTask(*study, task, takes_packed_values ? ValueEncoding::kPacked : ValueEncoding::kUnpacked, &result,
                     analyzer.has_value() ? &*analyzer : nullptr, analysis_budget);
        FitResultToServerLimit(max_message_bytes, max_result_bytes, &result);
      } else if (!study_error.empty()) {
        // Not the design point's fault: let another worker try.
        result.set_ok(false);
        result.set_retry(true);
        result.set_failure_reason(study_error);
      } else {
        deliver = false;  // the job is gone or the server unreachable
      }
      if (options_.verbose) {
        Log(absl::StrCat("task ", task.task_id(), result.ok() ? " ok" : " failed: ",
                         result.ok() ? "" : result.failure_reason()));
      }
      // After the line above, so that a test reading it knows the worker
      // holds the result for this long. A stop ends the hold early.
      if (options_.task_delay_ms > 0 && deliver) stop_.WaitFor(std::chrono::milliseconds(options_.task_delay_ms));
      // Results of cheap analyses are held while more tasks of this worker
      // wait to run, and go back together (one call, one commit on the
      // server) once none does, when they approach the server's message
      // limit, or after kMaxHold.
      const std::int64_t budget = max_message_bytes > 0 ? max_message_bytes / 2 : kDefaultBatchBytes;
      std::vector<std::vector<v1::TaskResult>> batches;
      int next_tasks = 0;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        cancel_flags_.erase(task.task_id());
        if (cancelled_[task.task_id()]) deliver = false;
        if (!deliver) {
          cancelled_.erase(task.task_id());
          --busy_;
        } else {
          const std::int64_t bytes = static_cast<std::int64_t>(result.ByteSizeLong());
          if (!held_.empty() && held_bytes_ + bytes > budget) {
            batches.emplace_back();
            batches.back().swap(held_);
            held_bytes_ = 0;
          }
          if (held_.empty()) held_since_ = std::chrono::steady_clock::now();
          held_.push_back(std::move(result));
          held_bytes_ += bytes;
        }
        const auto now = std::chrono::steady_clock::now();
        if (!held_.empty() && (queue_.empty() || stopping_ || held_bytes_ > budget || now - started >= kCheapAnalysis ||
                               now - held_since_ >= kMaxHold)) {
          batches.emplace_back();
          batches.back().swap(held_);
          held_bytes_ = 0;
          // The slots free once these are in: ask for their next tasks with
          // them, unless tasks are already queued here.
          if (!stopping_ && queue_.empty()) {
            next_tasks = Capacity() - busy_ + static_cast<int>(batches.back().size());
          }
        }
      }
      for (size_t b = 0; b < batches.size(); ++b) {
        Deliver(std::move(batches[b]), b + 1 == batches.size() ? next_tasks : 0);
      }
      cv_.notify_all();
    }
  }

  // Reports a batch of results (moved into the call, not copied: a result
  // may be megabytes), frees their places, and queues the up to
  // `next_tasks` tasks the server handed out with its answer, leased under
  // the current registration. Each result keeps the registration its own
  // task came under.
  void Deliver(std::vector<v1::TaskResult> results, int next_tasks) {
    v1::TaskResults request;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      request.set_worker_id(worker_id_);
    }
    for (v1::TaskResult& r : results) request.mutable_results()->Add(std::move(r));
    request.set_next_tasks(next_tasks);
    const std::vector<v1::AnalysisTask> next = Report(request);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const v1::TaskResult& r : request.results()) cancelled_.erase(r.task_id());
      busy_ -= request.results_size();
    }
    for (const v1::AnalysisTask& task : next) Take(task, request.worker_id());
    cv_.notify_all();
  }

  // The job's prepared study, fetched once. nullptr with an empty `error`
  // if it cannot be fetched (job gone, server unreachable); nullptr with a
  // message if the study does not convert here (the task is then reported
  // with retry = true, for another worker to try).
  std::shared_ptr<const PreparedStudy> StudyFor(const std::string& job_id, std::string* error) {
    std::lock_guard<std::mutex> lock(study_mutex_);
    if (auto it = studies_.find(job_id); it != studies_.end()) return it->second;
    if (auto it = study_errors_.find(job_id); it != study_errors_.end()) {
      *error = it->second;
      return nullptr;
    }
    Backoff backoff(options_.backoff, backoff_seed_ + 1);
    const auto give_up = Clock::now() + kReportRetryWindow;
    v1::GetStudyResponse response;
    while (true) {
      v1::GetStudyRequest request;
      request.set_job_id(job_id);
      grpc::ClientContext context;
      context.set_deadline(Clock::now() + kShortCallDeadline);
      grpc::Status status;
      {
        ScopedCall scoped(calls_, &context);
        status = stub_->GetStudy(&context, request, &response);
      }
      if (status.ok()) break;
      if (!Retryable(status) || stop_.stopped() || Clock::now() > give_up) {
        Log(absl::StrCat("cannot get the study of job ", job_id, ": ", status.error_message()));
        return nullptr;
      }
      if (stop_.WaitFor(backoff.Next())) return nullptr;
    }
    if (studies_.size() + study_errors_.size() >= kMaxCachedStudies) {
      studies_.clear();
      study_errors_.clear();
    }
    auto prepared = PrepareStudy(response.study(), job_id);
    if (!prepared.ok()) {
      *error = absl::StrCat("the study of job ", job_id,
                            " cannot be prepared: ", prepared.status().message());
      study_errors_[job_id] = *error;
      return nullptr;
    }
    studies_[job_id] = *prepared;
    return *prepared;
  }

  // Delivers results; returns the tasks the server leased with its answer.
  // A result over the message limit (alone in its batch: batches stay
  // under half the limit) goes in pieces.
  std::vector<v1::AnalysisTask> Report(const v1::TaskResults& request) {
    std::int64_t max_message_bytes = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      max_message_bytes = max_message_bytes_;
    }
    const bool in_pieces =
        request.results_size() == 1 &&
        !FitsOneMessage(static_cast<std::int64_t>(request.ByteSizeLong()), max_message_bytes);
    const std::string serialized = in_pieces ? request.results(0).SerializeAsString() : std::string();
    Backoff backoff(options_.backoff, backoff_seed_ + 2);
    const auto give_up = Clock::now() + kReportRetryWindow;
    while (true) {
      v1::ReportResultsResponse response;
      grpc::ClientContext context;
      // Pieces take as long as their bytes do: a second per 10 MB on top.
      context.set_deadline(Clock::now() + kShortCallDeadline +
                           std::chrono::seconds(static_cast<std::int64_t>(serialized.size()) / 10'000'000));
      // Not registered for cancellation: a result finished while stopping is
      // still worth delivering.
      grpc::Status status = in_pieces ? SendInPieces(&context, request, serialized, max_message_bytes, &response)
                                      : stub_->ReportResults(&context, request, &response);
      if (status.ok()) {
        std::int64_t delivered = 0;
        {
          std::lock_guard<std::mutex> lock(mutex_);
          delivered = results_delivered_ += request.results_size();
        }
        Log(BatchLogLine(request, delivered));
        for (int i = 0; i < response.answers_size() && i < request.results_size(); ++i) {
          const v1::ResultAnswer& answer = response.answers(i);
          if (!answer.error().empty()) {
            Log(absl::StrCat("result of task ", request.results(i).task_id(), " refused: ", answer.error()));
          } else if (!answer.accepted() && options_.verbose) {
            Log(absl::StrCat("result of task ", request.results(i).task_id(), " was not accepted"));
          }
        }
        return {response.tasks().begin(), response.tasks().end()};
      }
      if (!Retryable(status) || stop_.stopped() || Clock::now() > give_up) {
        const int n = request.results_size();
        Log(absl::StrCat(n == 1 ? "result of task " : "results of tasks ", request.results(0).task_id(),
                         n > 1 ? absl::StrCat(" and ", n - 1, " more") : "", " not delivered: ", status.error_message()));
        return {};
      }
      if (stop_.WaitFor(backoff.Next())) return {};
    }
  }

  // ReportResultInPieces with `serialized` (the one result of `request`),
  // cut into pieces of half a message.
  grpc::Status SendInPieces(grpc::ClientContext* context, const v1::TaskResults& request,
                            const std::string& serialized, std::int64_t max_message_bytes,
                            v1::ReportResultsResponse* response) {
    std::unique_ptr<grpc::ClientWriter<v1::ResultPiece>> writer = stub_->ReportResultInPieces(context, response);
    const size_t piece_bytes = static_cast<size_t>(std::max<std::int64_t>(max_message_bytes / 2, 4096));
    for (size_t at = 0; at < serialized.size(); at += piece_bytes) {
      v1::ResultPiece piece;
      if (at == 0) {
        piece.set_worker_id(request.worker_id());
        piece.set_total_bytes(static_cast<std::int64_t>(serialized.size()));
        piece.set_next_tasks(request.next_tasks());
      }
      piece.set_data(serialized.substr(at, piece_bytes));
      if (!writer->Write(piece)) break;  // the server ended the call: Finish says why
    }
    writer->WritesDone();
    return writer->Finish();
  }

  void HeartbeatLoop() {
    while (true) {
      int interval_ms;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        interval_ms = heartbeat_ms_;
      }
      if (stop_.WaitFor(std::chrono::milliseconds(interval_ms))) return;
      v1::HeartbeatRequest request;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (!registered_) continue;
        request.set_worker_id(worker_id_);
        for (const auto& [task_id, cancelled] : cancelled_) {
          if (!cancelled) request.add_task_ids(task_id);
        }
      }
      v1::HeartbeatResponse response;
      grpc::ClientContext context;
      context.set_deadline(Clock::now() + kShortCallDeadline);
      grpc::Status status;
      {
        ScopedCall scoped(calls_, &context);
        status = stub_->Heartbeat(&context, request, &response);
      }
      if (!status.ok()) continue;  // the acquiring thread handles reconnection
      std::lock_guard<std::mutex> lock(mutex_);
      if (!response.known() && worker_id_ == request.worker_id()) {
        Log("the server no longer knows this worker; registering again");
        registered_ = false;
      }
      for (const auto& task_id : response.cancelled_task_ids()) {
        auto it = cancelled_.find(task_id);
        if (it == cancelled_.end()) continue;
        it->second = true;
        if (auto flag = cancel_flags_.find(task_id); flag != cancel_flags_.end()) {
          flag->second->store(true, std::memory_order_relaxed);
          if (options_.verbose) Log(absl::StrCat("task ", task_id, " cancelled by the server"));
        }
        auto queued = std::find_if(queue_.begin(), queue_.end(), [&](const QueuedTask& q) {
          return q.task.task_id() == task_id;
        });
        if (queued != queue_.end()) {
          queue_.erase(queued);
          cancelled_.erase(it);
          cancel_flags_.erase(task_id);
          --busy_;
          cv_.notify_all();
        }
      }
    }
  }

  // Holds the server's Attach stream open while registered, so that the
  // server notices at once when this process dies (its connection closes)
  // and requeues the tasks in hand. The acquiring thread handles
  // reconnection; this one only follows the registration.
  void PresenceLoop() {
    while (true) {
      std::string worker_id;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait(lock, [this] { return stopping_ || (registered_ && attached_ != worker_id_); });
        if (stopping_) return;
        worker_id = worker_id_;
        attached_ = worker_id;
      }
      v1::AttachRequest request;
      request.set_worker_id(worker_id);
      grpc::ClientContext context;
      grpc::Status status;
      {
        ScopedCall scoped(calls_, &context);
        std::unique_ptr<grpc::ClientReader<v1::AttachEvent>> reader = stub_->Attach(&context, request);
        v1::AttachEvent event;
        const bool attached = reader->Read(&event);
        {
          std::lock_guard<std::mutex> lock(mutex_);
          attach_settled_ = worker_id;
        }
        cv_.notify_all();
        if (attached) {
          while (reader->Read(&event)) {
          }
        }
        status = reader->Finish();
      }
      if (status.error_code() == grpc::StatusCode::UNIMPLEMENTED && !attach_unavailable_logged_) {
        Log("the server cannot watch this worker's connection; a lost task waits for its lease");
        attach_unavailable_logged_ = true;
      }
      // Ended: the server stopped, restarted or forgot this registration.
      // Attach again once the acquiring thread has registered (or found the
      // registration still valid).
      if (stop_.WaitFor(std::chrono::milliseconds(500))) return;
      std::lock_guard<std::mutex> lock(mutex_);
      attached_.clear();
    }
  }

  WorkerOptions options_;
  StopSignal& stop_;
  const std::uint64_t backoff_seed_;
  std::unique_ptr<v1::WorkerService::Stub> stub_;
  CallRegistry calls_;

  std::mutex mutex_;
  std::condition_variable cv_;
  bool stopping_ = false;
  bool registered_ = false;
  std::string worker_id_;
  int heartbeat_ms_ = kDefaultHeartbeatMs;
  std::int64_t max_message_bytes_ = 0;  // the server's, from registration; 0: unknown
  std::int64_t max_result_bytes_ = 0;   // likewise, in pieces; 0: unknown or none
  bool takes_packed_values_ = false;    // likewise; false: send values unpacked
  std::deque<QueuedTask> queue_;
  int busy_ = 0;                          // tasks queued, being evaluated or held as results
  std::vector<v1::TaskResult> held_;      // results waiting to go back with others
  std::int64_t held_bytes_ = 0;
  std::chrono::steady_clock::time_point held_since_;  // when the oldest held result was held
  std::map<std::string, bool> cancelled_; // task id -> cancelled, for tasks in hand
  // Task id -> the cancel flag its analysis' budget reads, for tasks queued
  // or running (shared with the running analysis, which may outlive the entry).
  std::map<std::string, std::shared_ptr<std::atomic<bool>>> cancel_flags_;
  std::string attached_;        // the registration the presence thread holds (or tries)
  std::string attach_settled_;  // the registration whose Attach was answered
  bool attach_unavailable_logged_ = false;  // presence thread only

  std::mutex study_mutex_;
  std::map<std::string, std::shared_ptr<const PreparedStudy>> studies_;
  std::map<std::string, std::string> study_errors_;

  std::int64_t results_delivered_ = 0;  // guarded by mutex_; accepted by the server or not
  int tasks_received_ = 0;  // guarded by mutex_
  absl::Status fatal_;      // guarded by mutex_
  bool unreachable_logged_ = false;  // acquiring thread only
  bool ever_registered_ = false;     // acquiring thread only
};

}  // namespace

absl::Status RunWorker(const WorkerOptions& options, StopSignal& stop) {
  if (options.server_address.empty()) {
    return absl::InvalidArgumentError("--server ADDRESS is required");
  }
  if (options.slots < 1) {
    return absl::InvalidArgumentError(absl::StrCat("--slots must be >= 1, got ", options.slots));
  }
  if (options.die_after_tasks < 0) {
    return absl::InvalidArgumentError("--die-after-tasks must be >= 0");
  }
  auto worker = std::make_shared<Worker>(options, stop);
  worker->Run();
  return worker->fatal();
}

}  // namespace mbopt::worker
