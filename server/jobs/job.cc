#include "server/jobs/job.h"

#include <cstring>
#include <map>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/status_macros.h"
#include "server/jobs/problem_from_study.h"
#include "server/jobs/record_codec.h"
#include "server/lp/make_clp_lp_solver.h"

namespace mbopt::jobs {
namespace {

bool SameBits(const Eigen::VectorXd& a, const std::vector<double>& b) {
  return static_cast<size_t>(a.size()) == b.size() &&
         (b.empty() || std::memcmp(a.data(), b.data(), b.size() * sizeof(double)) == 0);
}

}  // namespace

absl::StatusOr<std::unique_ptr<Job>> Job::Create(spec::Study study) {
  MBOPT_ASSIGN_OR_RETURN(spec::StudyLayout layout, spec::MakeStudyLayout(study));
  MBOPT_ASSIGN_OR_RETURN(slp::ProblemSpec problem, ProblemSpecFromStudy(study, layout));
  MBOPT_ASSIGN_OR_RETURN(slp::SlpOptions options, SlpOptionsFromStudy(study));
  auto optimizer = std::make_unique<slp::SlpOptimizer>(std::move(problem), options, lp::MakeClpLpSolver());
  return std::unique_ptr<Job>(new Job(std::move(study), std::move(layout), options, std::move(optimizer)));
}

Job::Job(spec::Study study, spec::StudyLayout layout, slp::SlpOptions options,
         std::unique_ptr<slp::SlpOptimizer> optimizer)
    : study_(std::move(study)),
      layout_(std::move(layout)),
      options_(options),
      optimizer_(std::move(optimizer)) {}

absl::StatusOr<std::vector<slp::CycleRecord>> Job::Replay(const std::vector<LoggedAnalysis>& logged,
                                                          const std::vector<std::string>& logged_records) {
  std::map<std::int64_t, const LoggedAnalysis*> by_id;
  for (const LoggedAnalysis& a : logged) by_id[a.result.request_id] = &a;
  size_t next_record = 0;
  std::vector<slp::CycleRecord> unlogged;
  size_t used = 0;
  // One result at a time, re-asking the optimizer each time: a result that
  // completes a batch changes what is pending.
  while (true) {
    const LoggedAnalysis* next = nullptr;
    std::vector<slp::AnalysisRequest> pending = optimizer_->PendingRequests();
    const slp::AnalysisRequest* request = nullptr;
    for (const slp::AnalysisRequest& r : pending) {
      auto found = by_id.find(r.id);
      if (found != by_id.end()) {
        next = found->second;
        request = &r;
        break;
      }
    }
    if (next == nullptr) break;
    if (!SameBits(request->x, next->x_scaled)) {
      return absl::DataLossError(absl::StrCat(
          "replay of ", study_.name, ": request ", request->id,
          " asks for a different design point than the logged analysis; the optimizer is not "
          "deterministic or the database comes from another build"));
    }
    MBOPT_ASSIGN_OR_RETURN(std::vector<slp::CycleRecord> records, Submit(next->result));
    ++used;
    for (slp::CycleRecord& record : records) {
      if (next_record < logged_records.size()) {
        if (EncodeCycleRecord(record) != logged_records[next_record]) {
          return absl::DataLossError(absl::StrCat("replay of ", study_.name, ": cycle record ", next_record,
                                                  " (cycle ", record.cycle, ", attempt ", record.attempt,
                                                  ") differs from the logged one; the optimizer is not "
                                                  "deterministic or the database comes from another build"));
        }
      } else {
        unlogged.push_back(std::move(record));
      }
      ++next_record;
    }
  }
  if (next_record < logged_records.size()) {
    return absl::DataLossError(absl::StrCat("replay of ", study_.name, " produced ", next_record,
                                            " cycle records but the log holds ", logged_records.size()));
  }
  if (used != logged.size()) {
    return absl::DataLossError(absl::StrCat("replay of ", study_.name, " used ", used, " of ", logged.size(),
                                            " logged analyses; the others were never asked for"));
  }
  return unlogged;
}

absl::StatusOr<std::vector<slp::CycleRecord>> Job::Submit(const slp::AnalysisResult& result) {
  MBOPT_RETURN_IF_ERROR(optimizer_->SubmitResult(result));
  return optimizer_->TakeNewRecords();
}

std::vector<double> Job::PhysicalDesign(const Eigen::VectorXd& x_scaled) const {
  std::vector<double> design(static_cast<size_t>(x_scaled.size()));
  for (Eigen::Index i = 0; i < x_scaled.size() && static_cast<size_t>(i) < study_.variables.size(); ++i) {
    design[static_cast<size_t>(i)] = study_.variables[static_cast<size_t>(i)].scale * x_scaled[i];
  }
  return design;
}

}  // namespace mbopt::jobs
