// What a job needs from whoever runs its analyses when it drives itself to
// the end (Job::Run): one candidate record per request. The service does not
// use this interface: there, the job manager hands requests to the scheduler
// and feeds the workers' results back through the same Job::Intake and
// Job::Apply as Run does. In-process runs (tests/testing/local_run) and tests of
// the optimizer implement it.
#pragma once

#include <functional>
#include <vector>

#include "server/jobs/analysis_record.h"
#include "server/slp/slp_optimizer.h"

namespace mbopt::jobs {

class Evaluator {
 public:
  virtual ~Evaluator() = default;
  // One record per request of `batch`, in the same order, with request_id
  // and x_scaled set. A failed analysis is a record with its failure, never
  // an error. Must not throw.
  virtual std::vector<AnalysisRecord> Evaluate(const std::vector<slp::AnalysisRequest>& batch) = 0;
};

// An Evaluator from a function of one request (tests, analytic problems).
class FunctionEvaluator : public Evaluator {
 public:
  using Function = std::function<AnalysisRecord(const slp::AnalysisRequest&)>;
  explicit FunctionEvaluator(Function evaluate) : evaluate_(std::move(evaluate)) {}
  std::vector<AnalysisRecord> Evaluate(const std::vector<slp::AnalysisRequest>& batch) override {
    std::vector<AnalysisRecord> records;
    records.reserve(batch.size());
    for (const slp::AnalysisRequest& request : batch) {
      AnalysisRecord record = evaluate_(request);
      record.request_id = request.id;
      record.x_scaled.assign(request.x.data(), request.x.data() + request.x.size());
      records.push_back(std::move(record));
    }
    return records;
  }

 private:
  Function evaluate_;
};

}  // namespace mbopt::jobs
