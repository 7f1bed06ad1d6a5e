#include "bench/compare/slp_method.h"

#include <cmath>

#include "common/status_macros.h"
#include "tests/testing/local_run/local_run.h"

namespace mbopt::compare {

absl::StatusOr<MethodRun> RunSlpMethod(const spec::Study& study) {
  MethodRun run;
  run.method = "mbopt SLP";
  run.study = study.name;
  local_run::LocalRunOptions options;
  options.on_record = [&run](const slp::CycleRecord& r) {
    if (r.cycle == 1 && r.attempt == 0) {
      run.candidates.push_back(Candidate{1, r.objective_x0, r.max_violation_x0});
    }
    if (!r.accepted) ++run.rejected_trials;
    if (std::isfinite(r.objective_trial)) {
      run.candidates.push_back(Candidate{r.analyses_total, r.objective_trial, r.max_violation_trial});
    }
  };
  MBOPT_ASSIGN_OR_RETURN(local_run::LocalRunResult result, local_run::RunStudyLocally(study, options));
  run.final_objective = result.outcome.objective;
  run.final_max_violation = result.outcome.max_violation;
  run.analyses = result.outcome.analyses;
  run.failed_analyses = result.analyses_failed;
  run.wall_seconds = result.wall_seconds;
  run.cycles = result.outcome.cycles;
  run.num_variables = static_cast<int>(study.variables.size());
  run.end = slp::RunStateName(result.outcome.state);
  if (!result.end_reason.empty()) run.end += " (" + result.end_reason + ")";
  return run;
}

}  // namespace mbopt::compare
