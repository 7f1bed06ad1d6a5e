#include "server/service/grpc_services.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <string>

#include "absl/cleanup/cleanup.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "server/service/audit_log.h"
#include "server/service/proto_convert.h"
#include "server/service/status_conversion.h"

namespace mbopt::service {
namespace {

// How often a Watch stream checks whether its client went away.
constexpr std::int64_t kWatchPollMs = 250;
// The most drivers a worker's registration keeps.
constexpr int kMaxDeclaredDrivers = 1000;
constexpr std::int64_t kSummaryIntervalMs = 50;

std::int64_t NowUnixMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

// ------------------------------------------------------------------ jobs --

absl::StatusOr<auth::Principal> JobServiceImpl::CheckJobAccess(const grpc::ServerContext& context,
                                                               const char* method, const std::string& job_id) const {
  absl::StatusOr<auth::Principal> caller = authorizer_->ForJobs(context, method);
  if (!caller.ok()) return caller.status();
  absl::StatusOr<std::string> owner = manager_->OwnerOf(job_id);
  if (!owner.ok()) return owner.status();
  if (!CallAuthorizer::MaySee(*caller, *owner)) {
    // The answer for a job that does not exist: the caller learns nothing
    // of other users' jobs. The log says what happened.
    AuditLog(absl::StrCat("refused ", method, " from ", CallAuthorizer::Caller(context, &*caller), ": job '", job_id,
                          "' is another user's (", *owner, "); answered as if it did not exist"));
    return jobs::manager::JobManager::NoSuchJob(job_id);
  }
  return caller;
}

grpc::Status JobServiceImpl::Submit(grpc::ServerContext* context, const v1::SubmitJobRequest* request,
                                    v1::SubmitJobResponse* response) {
  absl::StatusOr<auth::Principal> caller = authorizer_->ForJobs(*context, "Submit");
  if (!caller.ok()) return ToGrpcStatus(caller.status());
  if (request->study().empty()) return ToGrpcStatus(absl::InvalidArgumentError("SubmitJobRequest.study is missing"));
  // A study comes from files of at most kMaxInputFileBytes each (its own and
  // its scene's) and an FMU of at most kMaxFmuArchiveBytes; a larger message did not, and is refused before it is
  // decoded, stored or sent to workers.
  const std::size_t study_bytes = request->study().size();
  if (study_bytes > kMaxStudyMessageBytes) {
    return ToGrpcStatus(absl::InvalidArgumentError(
        absl::StrFormat("SubmitJobRequest.study is %.1f MB, more than the limit of %d MB", study_bytes / 1048576.0,
                        static_cast<int>(kMaxStudyMessageBytes >> 20))));
  }
  if (request->source_name().size() > kMaxSourceNameBytes) {
    return ToGrpcStatus(absl::InvalidArgumentError(absl::StrCat("SubmitJobRequest.source_name has ",
                                                                request->source_name().size(),
                                                                " bytes, more than the limit of ", kMaxSourceNameBytes)));
  }
  // The study's own name is known only once it is decoded (by the job
  // manager); without a file name its messages say "the submitted study".
  const std::string source = request->source_name().empty() ? "the submitted study" : request->source_name();
  const std::string who = CallAuthorizer::Caller(*context, &*caller);
  absl::StatusOr<std::string> id = manager_->Submit(request->study(), source, caller->name, who);
  if (!id.ok()) return ToGrpcStatus(id.status());
  AuditLog(absl::StrCat("submit ", *id, " by ", who, ": ", source));
  response->set_job_id(*id);
  return grpc::Status::OK;
}

grpc::Status JobServiceImpl::Get(grpc::ServerContext* context, const v1::JobRef* request,
                                 v1::GetJobResponse* response) {
  if (absl::StatusOr<auth::Principal> access = CheckJobAccess(*context, "Get", request->job_id()); !access.ok()) {
    return ToGrpcStatus(access.status());
  }
  absl::StatusOr<jobs::manager::JobView> view = manager_->Get(request->job_id());
  if (!view.ok()) return ToGrpcStatus(view.status());
  *response->mutable_summary() = ToProto(view->summary);
  for (const slp::CycleRecord& r : view->records) {
    *response->add_cycles() = ToProto(r, *view);
  }
  SetSerializedMessageField(v1::GetJobResponse::kStudyFieldNumber, view->study_bytes, response);
  absl::StatusOr<std::vector<store::AnalysesByHolder>> computed_by = manager_->ComputedBy(request->job_id());
  if (!computed_by.ok()) return ToGrpcStatus(computed_by.status());
  for (const store::AnalysesByHolder& count : *computed_by) {
    v1::AnalysesByHolder* out = response->add_computed_by();
    out->set_holder(count.holder);
    out->set_analyses(count.analyses);
  }
  return grpc::Status::OK;
}

grpc::Status JobServiceImpl::List(grpc::ServerContext* context, const v1::ListJobsRequest*,
                                  v1::ListJobsResponse* response) {
  absl::StatusOr<auth::Principal> caller = authorizer_->ForJobs(*context, "List");
  if (!caller.ok()) return ToGrpcStatus(caller.status());
  absl::StatusOr<std::vector<jobs::manager::JobSummaryData>> summaries = manager_->List();
  if (!summaries.ok()) return ToGrpcStatus(summaries.status());
  for (const jobs::manager::JobSummaryData& s : *summaries) {
    if (CallAuthorizer::MaySee(*caller, s.owner)) *response->add_jobs() = ToProto(s);
  }
  return grpc::Status::OK;
}

grpc::Status JobServiceImpl::ListWorkers(grpc::ServerContext* context, const v1::ListWorkersRequest*,
                                         v1::ListWorkersResponse* response) {
  // Users see every worker: a worker belongs to the server, not to a job,
  // and nothing listed lets anyone act as one (docs/server.md, "Security").
  absl::StatusOr<auth::Principal> caller = authorizer_->ForJobs(*context, "ListWorkers");
  if (!caller.ok()) return ToGrpcStatus(caller.status());
  for (const scheduler::WorkerView& w : manager_->Workers()) {
    v1::WorkerSummary* out = response->add_workers();
    out->set_id(w.public_id);
    out->set_name(w.name);
    out->set_holder(w.holder);
    out->set_slots(w.slots);
    for (const std::string& driver : w.capabilities.drivers) out->add_drivers(driver);
    out->set_fmu_platform(w.capabilities.fmu_platform);
    out->set_analyses_done(w.analyses_done);
    out->set_tasks_held(w.tasks_held);
    out->set_silent_ms(w.silent_ms);
    out->set_quarantined(w.quarantined);
  }
  return grpc::Status::OK;
}

grpc::Status JobServiceImpl::Watch(grpc::ServerContext* context, const v1::JobRef* request,
                                   grpc::ServerWriter<v1::JobEvent>* writer) {
  if (absl::StatusOr<auth::Principal> access = CheckJobAccess(*context, "Watch", request->job_id()); !access.ok()) {
    return ToGrpcStatus(access.status());
  }
  absl::StatusOr<PeerCallLimiter::Slot> held = authorizer_->HoldCall(*context, "Watch");
  if (!held.ok()) return ToGrpcStatus(held.status());
  if (absl::Status status = manager_->StartWatching(request->job_id()); !status.ok()) return ToGrpcStatus(status);
  absl::Cleanup stop_watching = [this, request] { manager_->StopWatching(request->job_id()); };
  std::size_t next_record = 0;
  std::int64_t version = -1;
  // A job of cheap analyses changes hundreds of times a second; a summary
  // that brings no record goes out at most every kSummaryIntervalMs (the
  // last one held back is sent when the interval ends), so watching does not
  // cost the server a message per batch of results. Records and the final
  // summary go out at once. The interval is on the server's clock.
  std::optional<v1::JobEvent> held_summary;
  std::optional<std::int64_t> last_summary_ms;
  auto summary_due = [&] { return !last_summary_ms || clock_->NowMs() >= *last_summary_ms + kSummaryIntervalMs; };
  // `event` may be the held summary itself: it is written before it is dropped.
  auto write_summary = [&](const v1::JobEvent& event) {
    last_summary_ms = clock_->NowMs();
    const bool written = writer->Write(event);
    held_summary.reset();
    return written;
  };
  while (!context->IsCancelled()) {
    std::int64_t wait_ms = kWatchPollMs;
    if (held_summary) {
      // A summary is held only after one was written.
      wait_ms = std::clamp<std::int64_t>(*last_summary_ms + kSummaryIntervalMs - clock_->NowMs(), 0, kWatchPollMs);
    }
    absl::StatusOr<jobs::manager::JobView> view =
        version < 0 ? manager_->Get(request->job_id(), 0, jobs::manager::JobViewFor::kWatcher)
                    : manager_->WaitForChange(request->job_id(), next_record, version, wait_ms);
    if (!view.ok()) return ToGrpcStatus(view.status());
    if (view->version == version) {
      if (held_summary && summary_due() && !write_summary(*held_summary)) return grpc::Status::CANCELLED;
      continue;
    }
    version = view->version;
    for (const slp::CycleRecord& r : view->records) {
      v1::JobEvent event;
      *event.mutable_cycle() = ToProto(r, *view);
      if (!writer->Write(event)) return grpc::Status::CANCELLED;
    }
    next_record = view->first_record + view->records.size();
    v1::JobEvent summary;
    *summary.mutable_summary() = ToProto(view->summary);
    if (view->records.empty() && !view->ended && !summary_due()) {
      held_summary = std::move(summary);
      continue;
    }
    if (!write_summary(summary)) return grpc::Status::CANCELLED;
    if (view->ended) return grpc::Status::OK;
  }
  return grpc::Status::CANCELLED;
}

grpc::Status JobServiceImpl::Cancel(grpc::ServerContext* context, const v1::JobRef* request,
                                    v1::JobSummary* response) {
  absl::StatusOr<auth::Principal> access = CheckJobAccess(*context, "Cancel", request->job_id());
  if (!access.ok()) return ToGrpcStatus(access.status());
  const std::string who = CallAuthorizer::Caller(*context, &*access);
  absl::StatusOr<jobs::manager::JobSummaryData> summary = manager_->Cancel(request->job_id(), who);
  AuditLog(absl::StrCat("cancel ", request->job_id(), " by ", who, ": ",
                        summary.ok() ? "done" : summary.status().message()));
  if (!summary.ok()) return ToGrpcStatus(summary.status());
  *response = ToProto(*summary);
  return grpc::Status::OK;
}

grpc::Status JobServiceImpl::Resume(grpc::ServerContext* context, const v1::JobRef* request,
                                    v1::JobSummary* response) {
  absl::StatusOr<auth::Principal> access = CheckJobAccess(*context, "Resume", request->job_id());
  if (!access.ok()) return ToGrpcStatus(access.status());
  const std::string who = CallAuthorizer::Caller(*context, &*access);
  absl::StatusOr<jobs::manager::JobSummaryData> summary = manager_->Resume(request->job_id(), who);
  AuditLog(absl::StrCat("resume ", request->job_id(), " by ", who, ": ",
                        summary.ok() ? "done" : summary.status().message()));
  if (!summary.ok()) return ToGrpcStatus(summary.status());
  *response = ToProto(*summary);
  return grpc::Status::OK;
}

// --------------------------------------------------------------- workers --

grpc::Status WorkerServiceImpl::Register(grpc::ServerContext* context, const v1::RegisterWorkerRequest* request,
                                         v1::RegisterWorkerResponse* response) {
  absl::StatusOr<auth::Principal> caller = authorizer_->ForWorkers(*context, "Register");
  if (!caller.ok()) return ToGrpcStatus(caller.status());
  scheduler::WorkerCapabilities capabilities;
  // Bounded as every name a client sends: a worker may declare many
  // drivers, each a file-safe name of at most 100 characters.
  for (int i = 0; i < request->drivers_size() && i < kMaxDeclaredDrivers; ++i) {
    capabilities.drivers.push_back(request->drivers(i).substr(0, 100));
  }
  capabilities.fmu_platform = request->fmu_platform().substr(0, 100);
  const std::string worker_id =
      scheduler_->RegisterWorker(request->name(), request->slots(), capabilities, caller->name);
  // Ties the id in the job log's analyses to a name and an address.
  AuditLog(absl::StrCat("worker ", scheduler::PublicWorkerId(worker_id), " registered by ",
                        CallAuthorizer::Caller(*context, &*caller), ", name '", request->name().substr(0, 256), "', ",
                        request->slots(), " slots",
                        capabilities.drivers.empty() ? "" : absl::StrCat(", drivers ", absl::StrJoin(capabilities.drivers, " "))));
  response->set_worker_id(worker_id);
  response->set_heartbeat_interval_ms(static_cast<std::int32_t>(scheduler_->options().heartbeat_interval_ms));
  response->set_lease_ms(static_cast<std::int32_t>(scheduler_->options().lease_ms));
  response->set_max_message_bytes(max_message_bytes_);
  response->set_max_result_bytes(max_result_bytes_);
  response->set_takes_packed_values(true);
  return grpc::Status::OK;
}

void WorkerServiceImpl::AddTasks(const std::vector<scheduler::Task>& tasks,
                                 google::protobuf::RepeatedPtrField<v1::AnalysisTask>* out) const {
  const std::int64_t unix_now = NowUnixMs();
  const std::int64_t clock_now = clock_->NowMs();
  for (const scheduler::Task& t : tasks) {
    v1::AnalysisTask* task = out->Add();
    task->set_task_id(t.task_id);
    task->set_job_id(t.job_id);
    task->set_request_id(t.request_id);
    task->mutable_x_scaled()->Add(t.x_scaled.begin(), t.x_scaled.end());
    task->set_lease_deadline_unix_ms(unix_now + (t.lease_deadline_ms - clock_now));
    task->set_want_gradients(t.want_gradients);
  }
}

grpc::Status WorkerServiceImpl::AcquireTasks(grpc::ServerContext* context, const v1::AcquireTasksRequest* request,
                                             v1::AcquireTasksResponse* response) {
  if (absl::StatusOr<auth::Principal> caller = authorizer_->ForWorkers(*context, "AcquireTasks"); !caller.ok()) {
    return ToGrpcStatus(caller.status());
  }
  const std::int64_t wait_ms = std::clamp<std::int64_t>(request->wait_ms(), 0, kMaxWaitMs);
  // Only a long poll holds its thread.
  absl::StatusOr<PeerCallLimiter::Slot> held =
      wait_ms > 0 ? authorizer_->HoldCall(*context, "AcquireTasks") : PeerCallLimiter::Slot();
  if (!held.ok()) return ToGrpcStatus(held.status());
  absl::StatusOr<std::vector<scheduler::Task>> tasks =
      scheduler_->AcquireWait(request->worker_id(), std::clamp(request->max_tasks(), 1, kMaxTasksPerCall), wait_ms);
  if (!tasks.ok()) return ToGrpcStatus(tasks.status());
  AddTasks(*tasks, response->mutable_tasks());
  return grpc::Status::OK;
}

grpc::Status WorkerServiceImpl::GetStudy(grpc::ServerContext* context, const v1::GetStudyRequest* request,
                                         v1::GetStudyResponse* response) {
  if (absl::StatusOr<auth::Principal> caller = authorizer_->ForWorkers(*context, "GetStudy"); !caller.ok()) {
    return ToGrpcStatus(caller.status());
  }
  absl::StatusOr<std::string> bytes = manager_->StudyBytes(request->job_id());
  if (!bytes.ok()) return ToGrpcStatus(bytes.status());
  SetSerializedMessageField(v1::GetStudyResponse::kStudyFieldNumber, *bytes, response);
  return grpc::Status::OK;
}

grpc::Status WorkerServiceImpl::ReportResult(grpc::ServerContext* context, const v1::TaskResult* request,
                                             v1::ReportResultResponse* response) {
  absl::StatusOr<auth::Principal> caller = authorizer_->ForWorkers(*context, "ReportResult");
  if (!caller.ok()) return ToGrpcStatus(caller.status());
  const absl::StatusOr<bool> accepted =
      request->retry() ? ReportRetry(*request) : manager_->ReportResult(WorkerReportFromProto(*request, caller->name));
  if (absl::IsPermissionDenied(accepted.status())) {
    return ToGrpcStatus(CallAuthorizer::Refuse(*context, "ReportResult", &*caller, accepted.status()));
  }
  if (!accepted.ok()) return ToGrpcStatus(accepted.status());
  if (*accepted && !request->retry()) LogResultsTaken(*context, *caller, request->worker_id(), {request->job_id()});
  response->set_accepted(*accepted);
  LeaseNextTasks(request->worker_id(), request->next_tasks(), response->mutable_tasks());
  return grpc::Status::OK;
}

void WorkerServiceImpl::LogResultsTaken(const grpc::ServerContext& context, const auth::Principal& caller,
                                        const std::string& worker_id, std::vector<std::string> job_ids) const {
  // Only where tokens name the machines: a loopback server's log (and
  // `mbopt run`'s terminal) would gain a line per batch and learn nothing.
  if (!authorizer_->needs_tokens()) return;
  const std::size_t results = job_ids.size();
  std::sort(job_ids.begin(), job_ids.end());
  job_ids.erase(std::unique(job_ids.begin(), job_ids.end()), job_ids.end());
  AuditLog(absl::StrCat(results, results == 1 ? " result" : " results", " of ", absl::StrJoin(job_ids, ", "),
                        " taken from ", scheduler::PublicWorkerId(worker_id), ", sent by ",
                        CallAuthorizer::Caller(context, &caller)));
}

absl::StatusOr<bool> WorkerServiceImpl::ReportRetry(const v1::TaskResult& result) const {
  const absl::Status reported =
      manager_->ReportWorkerError(result.worker_id(), result.task_id(), result.failure_reason());
  // A retry request for a task that is not outstanding is simply dropped.
  if (absl::IsNotFound(reported)) return false;
  if (!reported.ok()) return reported;
  return true;
}

void WorkerServiceImpl::LeaseNextTasks(const std::string& worker_id, int next_tasks,
                                       google::protobuf::RepeatedPtrField<v1::AnalysisTask>* out) const {
  // The results may have made the next tasks (a cycle's trial point right
  // after its last perturbation): they go back on the same call.
  if (next_tasks <= 0) return;
  absl::StatusOr<std::vector<scheduler::Task>> tasks =
      scheduler_->Acquire(worker_id, std::min(next_tasks, kMaxTasksPerCall));
  if (tasks.ok()) AddTasks(*tasks, out);
}

grpc::Status WorkerServiceImpl::ReportResults(grpc::ServerContext* context, const v1::TaskResults* request,
                                              v1::ReportResultsResponse* response) {
  absl::StatusOr<auth::Principal> caller = authorizer_->ForWorkers(*context, "ReportResults");
  if (!caller.ok()) return ToGrpcStatus(caller.status());
  return TakeResults(*context, *caller, "ReportResults", *request, response);
}

grpc::Status WorkerServiceImpl::ReportResultInPieces(grpc::ServerContext* context,
                                                     grpc::ServerReader<v1::ResultPiece>* reader,
                                                     v1::ReportResultsResponse* response) {
  absl::StatusOr<auth::Principal> caller = authorizer_->ForWorkers(*context, "ReportResultInPieces");
  if (!caller.ok()) return ToGrpcStatus(caller.status());
  absl::StatusOr<PeerCallLimiter::Slot> held = authorizer_->HoldCall(*context, "ReportResultInPieces");
  if (!held.ok()) return ToGrpcStatus(held.status());
  v1::ResultPiece piece;
  if (!reader->Read(&piece)) return ToGrpcStatus(absl::InvalidArgumentError("a result in pieces without a piece"));
  const std::int64_t total = piece.total_bytes();
  // Refused before anything is held: the size is named on the first piece.
  if (total <= 0 || total > max_result_bytes_) {
    return ToGrpcStatus(absl::InvalidArgumentError(absl::StrFormat(
        "a result of %d bytes in pieces; the server takes results of 1 to %d bytes (mbopt-server --max-result-mb)",
        total, max_result_bytes_)));
  }
  v1::TaskResults request;
  request.set_worker_id(piece.worker_id());
  request.set_next_tasks(piece.next_tasks());
  std::string bytes;
  // Grown as pieces come, not reserved whole on the first piece's word.
  bytes.reserve(static_cast<size_t>(std::min<std::int64_t>(total, std::int64_t{64} << 20)));
  do {
    if (static_cast<std::int64_t>(bytes.size() + piece.data().size()) > total) {
      return ToGrpcStatus(absl::InvalidArgumentError(
          absl::StrFormat("the pieces of a result add up to more than its %d bytes", total)));
    }
    bytes += piece.data();
  } while (reader->Read(&piece));
  if (static_cast<std::int64_t>(bytes.size()) != total) {
    return ToGrpcStatus(absl::InvalidArgumentError(
        absl::StrFormat("the pieces of a result add up to %d of its %d bytes", bytes.size(), total)));
  }
  if (!request.add_results()->ParseFromString(bytes)) {
    return ToGrpcStatus(absl::InvalidArgumentError("the pieces of a result do not make a TaskResult"));
  }
  bytes.clear();
  bytes.shrink_to_fit();
  return TakeResults(*context, *caller, "ReportResultInPieces", request, response);
}

grpc::Status WorkerServiceImpl::TakeResults(const grpc::ServerContext& context, const auth::Principal& caller,
                                            const char* method, const v1::TaskResults& request,
                                            v1::ReportResultsResponse* response) {
  std::vector<jobs::manager::WorkerReport> reports;
  std::vector<int> report_index;  // the answer of each report
  // Each result names the registration its task was leased under (a worker
  // that registered again may still report tasks of the old one).
  for (int i = 0; i < request.results_size(); ++i) {
    const v1::TaskResult& result = request.results(i);
    v1::ResultAnswer* answer = response->add_answers();
    if (result.retry()) {
      const absl::StatusOr<bool> accepted = ReportRetry(result);
      if (accepted.ok()) {
        answer->set_accepted(*accepted);
      } else {
        answer->set_error(std::string(accepted.status().message()));
      }
      continue;
    }
    reports.push_back(WorkerReportFromProto(result, caller.name));
    report_index.push_back(i);
  }
  const std::vector<absl::StatusOr<bool>> taken = manager_->ReportResults(std::move(reports));
  std::vector<std::string> taken_jobs;
  for (size_t k = 0; k < taken.size(); ++k) {
    v1::ResultAnswer* answer = response->mutable_answers(report_index[k]);
    if (taken[k].ok()) {
      answer->set_accepted(*taken[k]);
      if (*taken[k]) taken_jobs.push_back(request.results(report_index[k]).job_id());
    } else if (absl::IsUnavailable(taken[k].status())) {
      return ToGrpcStatus(taken[k].status());  // the server is stopping: the worker retries the call
    } else if (absl::IsPermissionDenied(taken[k].status())) {
      answer->set_error(std::string(CallAuthorizer::Refuse(context, method, &caller, taken[k].status()).message()));
    } else {
      answer->set_error(std::string(taken[k].status().message()));
    }
  }
  if (!taken_jobs.empty()) LogResultsTaken(context, caller, request.worker_id(), taken_jobs);
  LeaseNextTasks(request.worker_id(), request.next_tasks(), response->mutable_tasks());
  return grpc::Status::OK;
}

grpc::Status WorkerServiceImpl::Attach(grpc::ServerContext* context, const v1::AttachRequest* request,
                                       grpc::ServerWriter<v1::AttachEvent>* writer) {
  if (absl::StatusOr<auth::Principal> caller = authorizer_->ForWorkers(*context, "Attach"); !caller.ok()) {
    return ToGrpcStatus(caller.status());
  }
  absl::StatusOr<PeerCallLimiter::Slot> held = authorizer_->HoldCall(*context, "Attach");
  if (!held.ok()) return ToGrpcStatus(held.status());
  const std::string& worker_id = request->worker_id();
  if (!scheduler_->IsKnownWorker(worker_id)) {
    return ToGrpcStatus(absl::NotFoundError(absl::StrCat("no worker '", worker_id, "': register again")));
  }
  // Tells the worker it is attached: it takes tasks only after this.
  if (!writer->Write(v1::AttachEvent())) {
    manager_->WorkerLost(worker_id);
    return grpc::Status::CANCELLED;
  }
  // The sync API has no callback for a closed connection, so the stream
  // looks every kAttachPollMs: that bounds how late a loss is noticed.
  while (!context->IsCancelled()) {
    if (scheduler_->WaitForShutdown(kAttachPollMs)) return grpc::Status::OK;  // the server stops
  }
  manager_->WorkerLost(worker_id);
  return grpc::Status::CANCELLED;
}

grpc::Status WorkerServiceImpl::Heartbeat(grpc::ServerContext* context, const v1::HeartbeatRequest* request,
                                          v1::HeartbeatResponse* response) {
  if (absl::StatusOr<auth::Principal> caller = authorizer_->ForWorkers(*context, "Heartbeat"); !caller.ok()) {
    return ToGrpcStatus(caller.status());
  }
  std::vector<std::string> task_ids(request->task_ids().begin(), request->task_ids().end());
  scheduler::HeartbeatReply reply = scheduler_->Heartbeat(request->worker_id(), task_ids);
  response->set_known(reply.known);
  for (const std::string& id : reply.cancelled_task_ids) response->add_cancelled_task_ids(id);
  return grpc::Status::OK;
}

}  // namespace mbopt::service
