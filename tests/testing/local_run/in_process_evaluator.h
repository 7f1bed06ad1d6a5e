// A job's evaluator that runs every analysis in this process, one after
// another, with the engine's one study evaluation
// (worker/engine/evaluate_study.h): what a worker would compute, without the
// service. Pure: no threads, no I/O.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "server/jobs/evaluator.h"
#include "spec/analysis_outcome.h"
#include "spec/layout.h"
#include "spec/study.h"

namespace mbopt::local_run {

class InProcessEvaluator : public jobs::Evaluator {
 public:
  // Called before each analysis; a returned reason makes that analysis fail
  // (kind kInjected) without running the engine: fault injection for tests.
  using FailureInjector = std::function<std::optional<std::string>(const slp::AnalysisRequest&)>;

  // `study` and `layout` (MakeStudyLayout(study)) must outlive the evaluator.
  InProcessEvaluator(const spec::Study& study, const spec::StudyLayout& layout, FailureInjector inject = nullptr)
      : study_(study), layout_(layout), inject_(std::move(inject)) {}

  std::vector<jobs::AnalysisRecord> Evaluate(const std::vector<slp::AnalysisRequest>& batch) override;

  // Sum of the counters of every analysis run (wall_seconds: their sum).
  const spec::AnalysisCounters& total_counters() const { return total_counters_; }
  std::int64_t analyses_run() const { return analyses_run_; }  // engine analyses, injected failures excluded

 private:
  jobs::AnalysisRecord EvaluateOne(const slp::AnalysisRequest& request);

  const spec::Study& study_;
  const spec::StudyLayout& layout_;
  FailureInjector inject_;
  spec::AnalysisCounters total_counters_;
  std::int64_t analyses_run_ = 0;
};

}  // namespace mbopt::local_run
