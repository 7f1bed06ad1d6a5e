// The run of a design set (a sweep or a sample, spec/design_set.h): one
// analysis per design, no optimization. It plays the part the SLP core plays
// in an optimization job and keeps its contract, so the job manager, the
// store, the scheduler and resume treat both alike: every design is a
// pending request at once (request id = the design's index), results
// arrive in any order, and one record per design is emitted in the designs'
// order (design k's once designs 0..k are all answered). So the record log
// is the same whatever the number of workers or the order of their
// results, and a replay of the logged analyses emits it again bit for bit.
//
// A study job made of child runs (a Pareto front's SLP runs) can keep the
// same shape: a list of runs each identified by its index, records emitted
// in index order.
//
// Pure: no I/O, no clock, no threads.
#pragma once

#include <cstdint>
#include <map>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/status.h"
#include "server/jobs/analysis_record.h"
#include "server/slp/problem.h"
#include "server/slp/slp_optimizer.h"

namespace mbopt::jobs {

class DesignSetRun {
 public:
  // `row_constraints[h]`: the study constraint of constraint row h (the
  // layout's ConstraintRow::constraint); `num_constraints` of the study.
  DesignSetRun(slp::ProblemSpec problem, std::vector<Eigen::VectorXd> designs, std::vector<int> row_constraints,
               int num_constraints);

  std::vector<slp::AnalysisRequest> PendingRequests() const;
  bool IsPending(std::int64_t request_id) const;
  // One design's result (validated by the job's intake). InvalidArgument
  // for a request that is not pending.
  absl::Status Submit(const AnalysisRecord& record);
  std::vector<slp::CycleRecord> TakeNewRecords();

  bool done() const { return emitted_ == designs_.size(); }
  std::int64_t size() const { return static_cast<std::int64_t>(designs_.size()); }
  // Designs whose records are emitted (the prefix answered in order).
  std::int64_t designs_done() const { return static_cast<std::int64_t>(emitted_); }
  std::int64_t analyses_used() const { return answered_; }
  const slp::ProblemSpec& spec() const { return problem_; }

 private:
  slp::CycleRecord RecordOf(std::size_t index, const AnalysisRecord& record) const;

  slp::ProblemSpec problem_;
  std::vector<Eigen::VectorXd> designs_;
  std::vector<int> row_constraints_;
  int num_constraints_;
  std::vector<bool> answered_flags_;
  std::int64_t answered_ = 0;
  // Results that arrived before a design ahead of them was answered.
  std::map<std::size_t, AnalysisRecord> waiting_;
  std::size_t emitted_ = 0;
  std::vector<slp::CycleRecord> new_records_;
};

}  // namespace mbopt::jobs
