#include "tests/server/fake_worker.h"

#include <algorithm>
#include <limits>

#include <gtest/gtest.h>

#include "tests/server/test_study.h"

namespace mbopt::testing {

FakeWorker::FakeWorker(std::shared_ptr<grpc::Channel> channel, std::uint32_t seed, const std::string& name)
    : stub_(v1::WorkerService::NewStub(channel)), rng_(seed) {
  grpc::ClientContext context;
  v1::RegisterWorkerRequest request;
  request.set_name(name);
  request.set_slots(1);
  v1::RegisterWorkerResponse response;
  grpc::Status status = stub_->Register(&context, request, &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
  worker_id_ = response.worker_id();
}

std::vector<v1::AnalysisTask> FakeWorker::Acquire(int max_tasks, int wait_ms) {
  grpc::ClientContext context;
  v1::AcquireTasksRequest request;
  request.set_worker_id(worker_id_);
  request.set_max_tasks(max_tasks);
  request.set_wait_ms(wait_ms);
  v1::AcquireTasksResponse response;
  grpc::Status status = stub_->AcquireTasks(&context, request, &response);
  if (!status.ok()) failed_ = true;
  if (!tolerate_errors_) {
    EXPECT_TRUE(status.ok()) << status.error_message();
  }
  return std::vector<v1::AnalysisTask>(response.tasks().begin(), response.tasks().end());
}

const v1::Study& FakeWorker::StudyOf(const std::string& job_id) {
  auto it = studies_.find(job_id);
  if (it != studies_.end()) return it->second;
  grpc::ClientContext context;
  v1::GetStudyRequest request;
  request.set_job_id(job_id);
  v1::GetStudyResponse response;
  grpc::Status status = stub_->GetStudy(&context, request, &response);
  if (!status.ok()) failed_ = true;
  if (!tolerate_errors_) {
    EXPECT_TRUE(status.ok()) << status.error_message();
  }
  if (!status.ok()) return studies_[""];
  return studies_[job_id] = response.study();
}

v1::TaskResult FakeWorker::ResultOf(const v1::AnalysisTask& task) {
  const std::vector<double> x(task.x_scaled().begin(), task.x_scaled().end());
  const v1::Study& study = StudyOf(task.job_id());
  absl::StatusOr<FakeValues> values = EvaluateAnalytically(study, x);
  EXPECT_TRUE(values.ok()) << values.status();
  v1::TaskResult result;
  result.set_worker_id(worker_id_);
  result.set_task_id(task.task_id());
  result.set_job_id(task.job_id());
  result.set_request_id(task.request_id());
  result.set_ok(values.ok());
  if (values.ok()) {
    for (double v : values->objective_terms) result.add_objective_terms(v);
    for (double v : values->constraint_values) result.add_constraint_values(v);
  }
  (task.want_gradients() ? tasks_wanting_gradients_ : tasks_without_gradients_) += 1;
  answered_request_ids_.push_back(task.request_id());
  if (values.ok() && task.want_gradients()) {
    if (gradient_mode_ == GradientMode::kNone) {
      result.set_gradients_unavailable("this fake worker has no gradients");
    } else {
      absl::StatusOr<FakeGradients> gradients = GradientsAnalytically(study, x);
      EXPECT_TRUE(gradients.ok()) << gradients.status();
      if (gradients.ok()) {
        for (double v : gradients->objective_gradients) result.add_objective_gradients(v);
        for (double v : gradients->constraint_gradients) result.add_constraint_gradients(v);
      }
      if (gradient_mode_ == GradientMode::kWrongSize) result.mutable_objective_gradients()->RemoveLast();
      if (gradient_mode_ == GradientMode::kNonFinite) {
        result.set_constraint_gradients(0, std::numeric_limits<double>::quiet_NaN());
      }
    }
  }
  return result;
}

grpc::Status FakeWorker::Answer(const v1::AnalysisTask& task, bool* accepted) {
  if (failed_) return grpc::Status(grpc::StatusCode::UNAVAILABLE, "server lost");
  const v1::TaskResult result = ResultOf(task);
  grpc::ClientContext context;
  v1::ReportResultResponse response;
  grpc::Status status = stub_->ReportResult(&context, result, &response);
  if (accepted != nullptr) *accepted = response.accepted();
  return status;
}

grpc::Status FakeWorker::AnswerTogether(const std::vector<v1::AnalysisTask>& tasks,
                                        v1::ReportResultsResponse* response) {
  v1::TaskResults request;
  request.set_worker_id(worker_id_);
  for (const v1::AnalysisTask& task : tasks) *request.add_results() = ResultOf(task);
  grpc::ClientContext context;
  return stub_->ReportResults(&context, request, response);
}

int FakeWorker::Run(int max_results) {
  int reported = 0;
  while ((max_results < 0 || reported < max_results) && !failed_) {
    if (backlog_.empty()) {
      backlog_ = Acquire(1000);
      if (backlog_.empty()) break;
      std::shuffle(backlog_.begin(), backlog_.end(), rng_);
    }
    const v1::AnalysisTask task = backlog_.front();
    backlog_.erase(backlog_.begin());
    bool accepted = false;
    grpc::Status status = Answer(task, &accepted);
    if (!status.ok() && tolerate_errors_) {
      failed_ = true;
      break;
    }
    EXPECT_TRUE(status.ok()) << status.error_message();
    EXPECT_TRUE(accepted) << task.task_id();
    ++reported;
  }
  return reported;
}

int FakeWorker::RunUntil(const std::atomic<bool>& stop, int wait_ms) {
  int reported = 0;
  while (!stop.load()) {
    std::vector<v1::AnalysisTask> tasks = Acquire(2, wait_ms);
    std::shuffle(tasks.begin(), tasks.end(), rng_);
    for (const v1::AnalysisTask& task : tasks) {
      bool accepted = false;
      grpc::Status status = Answer(task, &accepted);
      EXPECT_TRUE(status.ok()) << status.error_message();
      EXPECT_TRUE(accepted) << task.task_id();
      ++reported;
    }
  }
  return reported;
}

}  // namespace mbopt::testing
