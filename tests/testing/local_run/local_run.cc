#include "tests/testing/local_run/local_run.h"

#include <chrono>
#include <memory>
#include <utility>

#include "common/monotonic_clock.h"
#include "common/status_macros.h"
#include "server/jobs/job.h"
#include "server/lp/make_clp_lp_solver.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::local_run {

absl::StatusOr<engine::StudyEvaluation> EvaluateDesign(const spec::Study& study, const spec::StudyLayout& layout,
                                                       const Eigen::VectorXd& x_scaled, bool want_gradients) {
  return engine::EvaluateStudy(study, layout, std::vector<double>(x_scaled.data(), x_scaled.data() + x_scaled.size()),
                               want_gradients, nullptr, budget::AnalysisBudget(&MonotonicSeconds, nullptr));
}

absl::StatusOr<LocalRunResult> RunStudyLocally(const spec::Study& study, const LocalRunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  MBOPT_ASSIGN_OR_RETURN(std::unique_ptr<jobs::Job> job,
                         jobs::Job::Create(study, lp::MakeClpLpSolver(), options.slp_override));
  LocalRunResult out;
  out.layout = job->layout();
  InProcessEvaluator evaluator(job->study(), job->layout(), options.inject_failure);
  RunOutcome& run = out.outcome;
  jobs::JobRunOptions run_options;
  run_options.max_analyses = options.max_analyses;
  run_options.on_analysis = [&run](const jobs::AnalysisRecord& record) { run.results.push_back(record); };
  run_options.on_record = [&run, &options](const slp::CycleRecord& record) {
    if (options.on_record) options.on_record(record);
    run.records.push_back(record);
  };
  MBOPT_RETURN_IF_ERROR(job->Run(evaluator, run_options));

  const slp::SlpOptimizer& optimizer = job->optimizer();
  run.state = optimizer.state();
  const slp::DesignPoint best = optimizer.best_design();
  run.design = best.x;
  run.objective = best.objective;
  run.max_violation = best.max_violation;
  run.cycles = optimizer.cycles_completed();
  run.analyses = optimizer.analyses_used();
  out.end_reason = optimizer.end_reason();
  out.result_notes = optimizer.result_notes();
  out.total_counters = evaluator.total_counters();
  out.analyses_run = evaluator.analyses_run();
  out.failures_by_kind = job->failures_by_kind();
  for (const auto& [kind, count] : out.failures_by_kind) out.analyses_failed += count;

  const std::vector<double> x(run.design.data(), run.design.data() + run.design.size());
  const std::vector<double> parameters_si = study.ParameterValuesAt(x);
  for (size_t k = 0; k < study.variables.size(); ++k) {
    const spec::DesignVariable& v = study.variables[k];
    out.design_scaled.push_back(x[k]);
    out.design_physical.push_back(v.scale * x[k]);
    out.design_si.push_back(parameters_si[static_cast<size_t>(v.parameter)]);
  }
  out.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace mbopt::local_run
