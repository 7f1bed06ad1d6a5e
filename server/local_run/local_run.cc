#include "server/local_run/local_run.h"

#include <chrono>
#include <memory>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/status_macros.h"
#include "server/jobs/problem_from_study.h"
#include "server/local_run/evaluate_design.h"
#include "server/lp/make_clp_lp_solver.h"

namespace mbopt::local_run {
namespace {

void Accumulate(const engine::AnalysisCounters& c, engine::AnalysisCounters* total) {
  total->time_steps += c.time_steps;
  total->rhs_evaluations += c.rhs_evaluations;
  total->jacobian_evaluations += c.jacobian_evaluations;
  total->newton_iterations += c.newton_iterations;
  total->position_solves += c.position_solves;
  total->wall_seconds += c.wall_seconds;
}

}  // namespace

absl::StatusOr<LocalRunResult> RunStudyLocally(const spec::Study& study, const LocalRunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  LocalRunResult out;
  MBOPT_ASSIGN_OR_RETURN(out.layout, spec::MakeStudyLayout(study));
  MBOPT_ASSIGN_OR_RETURN(slp::ProblemSpec problem, jobs::ProblemSpecFromStudy(study, out.layout));
  slp::SlpOptions slp_options;
  if (options.slp_override.has_value()) {
    slp_options = *options.slp_override;
    MBOPT_RETURN_IF_ERROR(slp_options.Validate());
  } else {
    MBOPT_ASSIGN_OR_RETURN(slp_options, jobs::SlpOptionsFromStudy(study));
  }
  slp::SlpOptimizer optimizer(std::move(problem), slp_options, lp::MakeClpLpSolver());

  // The calling protocol of slp::RunToCompletion, with records handed to
  // on_record as they appear rather than at the end.
  slp::RunOutcome& run = out.outcome;
  while (optimizer.state() == slp::RunState::kRunning) {
    const std::vector<slp::AnalysisRequest> pending = optimizer.PendingRequests();
    if (pending.empty()) return absl::InternalError("optimizer is running but requests no analysis");
    if (optimizer.analyses_used() + static_cast<std::int64_t>(pending.size()) > options.max_analyses) {
      return absl::ResourceExhaustedError(
          absl::StrCat("study ", study.name, ": run needs more than ", options.max_analyses, " analyses"));
    }
    for (const slp::AnalysisRequest& request : pending) {
      slp::AnalysisResult result;
      std::optional<std::string> injected;
      if (options.inject_failure) injected = options.inject_failure(request);
      if (injected.has_value()) {
        result.outcome = slp::AnalysisOutcome::kFailed;
        result.failure_reason = absl::StrCat("injected: ", *injected);
      } else {
        MBOPT_ASSIGN_OR_RETURN(DesignEvaluation evaluation,
                               request.want_gradients
                                   ? EvaluateDesignWithGradients(study, out.layout, request.x)
                                   : EvaluateDesign(study, out.layout, request.x));
        ++out.analyses_run;
        Accumulate(evaluation.counters, &out.total_counters);
        result = ToAnalysisResult(evaluation);
      }
      if (result.outcome == slp::AnalysisOutcome::kFailed) ++out.analyses_failed;
      result.request_id = request.id;
      MBOPT_RETURN_IF_ERROR(optimizer.SubmitResult(result));
      run.results.push_back(std::move(result));
      for (slp::CycleRecord& record : optimizer.TakeNewRecords()) {
        if (options.on_record) options.on_record(record);
        run.records.push_back(std::move(record));
      }
    }
  }
  run.state = optimizer.state();
  run.design = optimizer.current_design();
  run.objective = optimizer.current_objective();
  run.max_violation = optimizer.current_max_violation();
  run.cycles = optimizer.cycles_completed();
  run.analyses = optimizer.analyses_used();
  out.end_reason = optimizer.end_reason();

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
