#include "client/watch.h"

#include <memory>

#include "client/design_set_format.h"
#include "client/pareto_format.h"
#include "client/interrupts.h"
#include "client/job_format.h"

namespace mbopt::client {
namespace {

void ClearProgress(const WatchOptions& options) {
  if (options.progress_line) std::fputs("\r\033[K", options.table_out);
}

void DrawProgress(const WatchOptions& options, const v1::JobSummary& s) {
  if (!options.progress_line) return;
  char objective[64] = "";
  if (s.cycles() > 0) std::snprintf(objective, sizeof objective, ", F = %.7g", s.objective());
  if (s.design_set()) {
    std::fprintf(options.table_out, "\r\033[K  %s: %d of %d %s, %lld analyses, %.1f s",
                 StateName(s.state()).c_str(), s.cycles(), s.max_cycles(), s.pareto() ? "points" : "designs",
                 static_cast<long long>(s.analyses()),
                 s.wall_seconds());
    std::fflush(options.table_out);
    return;
  }
  std::fprintf(options.table_out, "\r\033[K  %s: %d cycles, %lld analyses%s, %.1f s",
               StateName(s.state()).c_str(), s.cycles(), static_cast<long long>(s.analyses()),
               objective, s.wall_seconds());
  std::fflush(options.table_out);
}

// The study of a job, for the lines of its front's points; null when the
// server does not give it (the lines then show the raw values).
std::unique_ptr<v1::Study> StudyOfJob(v1::JobService::Stub& job_service, const std::string& job_id) {
  v1::GetJobResponse job;
  if (!GetJob(job_service, job_id, &job).ok() || !job.has_study()) return nullptr;
  return std::unique_ptr<v1::Study>(job.release_study());
}

}  // namespace

WatchOutcome WatchJob(v1::JobService::Stub& job_service, const std::string& address,
                      const std::string& job_id, const WatchOptions& options) {
  WatchOutcome outcome;
  grpc::ClientContext context;
  Interrupts::SetCancelTarget(&context);
  v1::JobRef ref;
  ref.set_job_id(job_id);
  auto reader = job_service.Watch(&context, ref);
  bool header_printed = false;
  const v1::Study* study = options.study;
  std::unique_ptr<v1::Study> fetched_study;
  bool study_asked = false;
  v1::JobEvent event;
  while (reader->Read(&event)) {
    if (event.has_cycle()) {
      if (options.table_out == nullptr) continue;
      // A front's points' runs' cycles: the watch shows the points.
      if (event.cycle().pareto_point() > 0) continue;
      ClearProgress(options);
      const bool design = event.cycle().design_set();
      const bool point = event.cycle().pareto();
      if (point && study == nullptr && !study_asked) {
        study_asked = true;
        fetched_study = StudyOfJob(job_service, job_id);
        study = fetched_study.get();
      }
      if (!header_printed) {
        std::fprintf(options.table_out, "%s\n",
                     (point ? ParetoWatchHeader(study) : design ? DesignWatchHeader() : CycleTableHeader()).c_str());
        header_printed = true;
      }
      std::fprintf(options.table_out, "%s\n",
                   (point    ? ParetoWatchRow(event.cycle(), study)
                    : design ? DesignWatchRow(event.cycle())
                             : CycleTableRow(event.cycle()))
                       .c_str());
      std::fflush(options.table_out);
    } else if (event.has_summary()) {
      outcome.summary = event.summary();
      if (options.table_out != nullptr) DrawProgress(options, outcome.summary);
    }
  }
  grpc::Status status = reader->Finish();
  Interrupts::SetCancelTarget(nullptr);
  if (options.table_out != nullptr) {
    ClearProgress(options);
    std::fflush(options.table_out);
  }
  if (Interrupts::interrupted()) {
    outcome.interrupted = true;
    return outcome;
  }
  if (!status.ok()) {
    outcome.failure = DescribeRpcFailure(status, address);
    return outcome;
  }
  outcome.ok = true;
  return outcome;
}

}  // namespace mbopt::client
