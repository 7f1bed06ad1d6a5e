// A worker for server tests, driven synchronously by the test: it takes every
// task on offer, answers them in a shuffled order with the analytic values of
// test_study.h, and repeats until the queue is empty. The server queues a
// job's next analyses inside the call that reports the previous result, so
// an empty queue after a round means every job it serves has ended (or is
// waiting for someone else). No threads, no sleeps.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "mbopt/v1/service.grpc.pb.h"

namespace mbopt::testing {

class FakeWorker {
 public:
  FakeWorker(std::shared_ptr<grpc::Channel> channel, std::uint32_t seed, const std::string& name = "fake");

  const std::string& worker_id() const { return worker_id_; }
  v1::WorkerService::Stub& stub() { return *stub_; }

  // Answers tasks until none is on offer or `max_results` results were
  // reported (< 0: no limit). Tasks taken but not answered when the limit
  // is reached are answered first by the next call. Returns the number of
  // results reported; fails the test on any RPC error.
  int Run(int max_results = -1);

  // Long-polls for tasks (waiting up to `wait_ms` each time) and answers
  // them until `stop` is set; for several workers on their own threads.
  int RunUntil(const std::atomic<bool>& stop, int wait_ms);

  // What the worker answers to a task that wants gradients.
  enum class GradientMode {
    kExact,      // the closed-form gradients (test_study.h)
    kNone,       // none, with a reason (as a worker whose engine has none)
    kWrongSize,  // one entry too few: the server must take it as none
    kNonFinite,  // a NaN entry: likewise
  };
  void SetGradientMode(GradientMode mode) { gradient_mode_ = mode; }
  // Tasks answered so far that asked for gradients, and that did not.
  int tasks_wanting_gradients() const { return tasks_wanting_gradients_; }
  int tasks_without_gradients() const { return tasks_without_gradients_; }
  // The request ids of the tasks answered so far, in the order answered.
  const std::vector<std::int64_t>& answered_request_ids() const { return answered_request_ids_; }

  // Instead of failing the test, an RPC error ends Run() and sets failed():
  // for tests that kill the server under the worker.
  void TolerateServerLoss() { tolerate_errors_ = true; }
  bool failed() const { return failed_; }

  // Takes up to `max_tasks` tasks without answering them.
  std::vector<v1::AnalysisTask> Acquire(int max_tasks, int wait_ms = 0);
  // Answers one task with its analytic values; returns the RPC status.
  grpc::Status Answer(const v1::AnalysisTask& task, bool* accepted = nullptr);
  // Answers `tasks` (of any jobs) in one ReportResults call.
  grpc::Status AnswerTogether(const std::vector<v1::AnalysisTask>& tasks, v1::ReportResultsResponse* response);
  // The result this worker would report for `task` (its analytic values,
  // its worker id), not sent: tests alter it to play a hostile worker.
  v1::TaskResult ResultOf(const v1::AnalysisTask& task);

 private:
  const v1::Study& StudyOf(const std::string& job_id);

  std::unique_ptr<v1::WorkerService::Stub> stub_;
  std::string worker_id_;
  std::mt19937 rng_;
  std::map<std::string, v1::Study> studies_;
  std::vector<v1::AnalysisTask> backlog_;
  GradientMode gradient_mode_ = GradientMode::kExact;
  int tasks_wanting_gradients_ = 0;
  int tasks_without_gradients_ = 0;
  std::vector<std::int64_t> answered_request_ids_;
  bool tolerate_errors_ = false;
  bool failed_ = false;  // taken, not answered yet
};

}  // namespace mbopt::testing
