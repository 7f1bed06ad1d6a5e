// What a job asks of the run of a Pareto front, whichever its number of
// objectives: the SLP core's contract (pending requests, results in, records
// out), so the job manager, the store and resume treat both alike.
// ParetoRun (pareto_run.h) runs a front of two objectives, ParetoGridRun
// (pareto_grid_run.h) one of three.
#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "server/jobs/analysis_record.h"
#include "server/slp/slp_optimizer.h"

namespace mbopt::jobs {

class FrontRun {
 public:
  virtual ~FrontRun() = default;

  virtual std::vector<slp::AnalysisRequest> PendingRequests() const = 0;
  virtual bool IsPending(std::int64_t request_id) const = 0;
  // One result (validated by the job's intake, in the study's shape).
  // InvalidArgument for a request that is not pending.
  virtual absl::Status Submit(const AnalysisRecord& record) = 0;
  virtual std::vector<slp::CycleRecord> TakeNewRecords() = 0;
  // Whether the runs' cycle records are emitted (the default); off for a
  // job whose log has none, so that its replay emits what it logged.
  virtual void LogRunCycles(bool log) = 0;

  virtual bool done() const = 0;
  virtual int size() const = 0;
  virtual int points_done() const = 0;
  virtual std::int64_t analyses_used() const = 0;
};

}  // namespace mbopt::jobs
