// The gRPC services (sync API): JobService for clients, WorkerService for
// workers. Each method translates the request, calls the job manager or the
// scheduler, and translates the answer; errors pass through ToGrpcStatus.
#pragma once

#include <cstdint>
#include <vector>

#include "mbopt/v1/service.grpc.pb.h"
#include "server/scheduler/clock.h"
#include "server/service/call_authorizer.h"
#include "server/scheduler/scheduler.h"
#include "server/jobs/manager/job_manager.h"
#include "spec/limits.h"

namespace mbopt::service {

class JobServiceImpl final : public v1::JobService::Service {
 public:
  // `authorizer` and `clock` are not owned and must outlive the service.
  // The clock paces Watch's progress summaries (the server's clock, so a
  // test decides when an interval has passed).
  JobServiceImpl(jobs::manager::JobManager* manager, const CallAuthorizer* authorizer, const scheduler::Clock* clock)
      : manager_(manager), authorizer_(authorizer), clock_(clock) {}

  // What Submit takes: a study message no larger than its two files and the
  // FMU archive it may carry may be (spec/limits.h), and a source name of a
  // path's length.
  static constexpr std::size_t kMaxStudyMessageBytes =
      2 * static_cast<std::size_t>(spec::kMaxInputFileBytes) + static_cast<std::size_t>(spec::kMaxFmuArchiveBytes);
  static constexpr std::size_t kMaxSourceNameBytes = 4096;

  grpc::Status Submit(grpc::ServerContext* context, const v1::SubmitJobRequest* request,
                      v1::SubmitJobResponse* response) override;
  grpc::Status Get(grpc::ServerContext* context, const v1::JobRef* request, v1::GetJobResponse* response) override;
  grpc::Status List(grpc::ServerContext* context, const v1::ListJobsRequest* request,
                    v1::ListJobsResponse* response) override;
  grpc::Status Watch(grpc::ServerContext* context, const v1::JobRef* request,
                     grpc::ServerWriter<v1::JobEvent>* writer) override;
  grpc::Status Cancel(grpc::ServerContext* context, const v1::JobRef* request, v1::JobSummary* response) override;
  grpc::Status Resume(grpc::ServerContext* context, const v1::JobRef* request, v1::JobSummary* response) override;
  grpc::Status ListWorkers(grpc::ServerContext* context, const v1::ListWorkersRequest* request,
                           v1::ListWorkersResponse* response) override;

 private:
  // The caller, when it may see the job (which exists). The same NotFound
  // for another user's job as for none (logged as a refusal).
  absl::StatusOr<auth::Principal> CheckJobAccess(const grpc::ServerContext& context, const char* method,
                                                 const std::string& job_id) const;

  jobs::manager::JobManager* manager_;
  const CallAuthorizer* authorizer_;
  const scheduler::Clock* clock_;
};

class WorkerServiceImpl final : public v1::WorkerService::Service {
 public:
  // The clock is the scheduler's (lease deadlines are on it).
  // `max_message_bytes` is what workers are told the server receives in
  // one message, `max_result_bytes` in pieces.
  WorkerServiceImpl(jobs::manager::JobManager* manager, scheduler::Scheduler* scheduler, const scheduler::Clock* clock,
                    std::int64_t max_message_bytes, std::int64_t max_result_bytes, const CallAuthorizer* authorizer)
      : manager_(manager),
        scheduler_(scheduler),
        clock_(clock),
        max_message_bytes_(max_message_bytes),
        max_result_bytes_(max_result_bytes),
        authorizer_(authorizer) {}

  grpc::Status Register(grpc::ServerContext* context, const v1::RegisterWorkerRequest* request,
                        v1::RegisterWorkerResponse* response) override;
  grpc::Status AcquireTasks(grpc::ServerContext* context, const v1::AcquireTasksRequest* request,
                            v1::AcquireTasksResponse* response) override;
  grpc::Status GetStudy(grpc::ServerContext* context, const v1::GetStudyRequest* request,
                        v1::GetStudyResponse* response) override;
  grpc::Status ReportResult(grpc::ServerContext* context, const v1::TaskResult* request,
                            v1::ReportResultResponse* response) override;
  grpc::Status ReportResults(grpc::ServerContext* context, const v1::TaskResults* request,
                             v1::ReportResultsResponse* response) override;
  grpc::Status ReportResultInPieces(grpc::ServerContext* context, grpc::ServerReader<v1::ResultPiece>* reader,
                                    v1::ReportResultsResponse* response) override;
  grpc::Status Heartbeat(grpc::ServerContext* context, const v1::HeartbeatRequest* request,
                         v1::HeartbeatResponse* response) override;
  grpc::Status Attach(grpc::ServerContext* context, const v1::AttachRequest* request,
                      grpc::ServerWriter<v1::AttachEvent>* writer) override;

  // The longest a long poll waits, whatever the worker asks.
  static constexpr std::int64_t kMaxWaitMs = 30'000;
  // The most tasks one call hands out (AcquireTasks, and the next tasks
  // with a result).
  static constexpr int kMaxTasksPerCall = 64;
  // How often an Attach stream checks whether its worker's connection
  // closed: how late a dead worker's tasks are handed out again, against a
  // wake-up per worker every period (20 ms cost the server 6 % of its CPU
  // with four workers).
  static constexpr std::int64_t kAttachPollMs = 100;

 private:
  jobs::manager::JobManager* manager_;
  scheduler::Scheduler* scheduler_;
  // A worker could not run a task (TaskResult.retry): its attempt fails.
  // Whether that was taken (false: the task was not outstanding any more).
  absl::StatusOr<bool> ReportRetry(const v1::TaskResult& result) const;
  // One audit line per call whose results were taken, naming the worker,
  // its token's holder and the jobs (on a server with tokens).
  void LogResultsTaken(const grpc::ServerContext& context, const auth::Principal& caller,
                       const std::string& worker_id, std::vector<std::string> job_ids) const;
  // ReportResults after `caller` was authorized for `method`. A result
  // for another worker's task is refused (its answer says why) and logged.
  grpc::Status TakeResults(const grpc::ServerContext& context, const auth::Principal& caller, const char* method,
                           const v1::TaskResults& request, v1::ReportResultsResponse* response);
  // Leases up to `next_tasks` tasks to the worker into `out` (none for 0).
  void LeaseNextTasks(const std::string& worker_id, int next_tasks,
                      google::protobuf::RepeatedPtrField<v1::AnalysisTask>* out) const;
  // Leased tasks into their wire form.
  void AddTasks(const std::vector<scheduler::Task>& tasks,
                google::protobuf::RepeatedPtrField<v1::AnalysisTask>* out) const;

  const scheduler::Clock* clock_;
  std::int64_t max_message_bytes_;
  std::int64_t max_result_bytes_;
  const CallAuthorizer* authorizer_;
};

}  // namespace mbopt::service
