#include "bench/accuracy/sweep_run.h"

#include <utility>

#include "common/status_macros.h"
#include "tests/testing/local_run/local_run.h"
#include "spec/io/study_io.h"

namespace mbopt::accuracy {

absl::StatusOr<spec::Study> StudyWith(const v1::Study& base, const std::string& source,
                                      const v1::AnalysisOverrides& analysis,
                                      const v1::OptimizerOptions& optimizer) {
  v1::Study s = base;
  // Proto3 merge copies only the fields the setting sets: the rest stay the
  // study's own.
  s.mutable_analysis()->MergeFrom(analysis);
  s.mutable_optimizer()->MergeFrom(optimizer);
  return spec::io::StudyFromProto(s, source);
}

absl::StatusOr<RecheckModel> MakeRecheckModel(const v1::Study& base, const std::string& source,
                                              const v1::AnalysisOverrides& recheck) {
  RecheckModel m;
  MBOPT_ASSIGN_OR_RETURN(m.study, StudyWith(base, source, recheck, v1::OptimizerOptions{}));
  MBOPT_ASSIGN_OR_RETURN(m.layout, spec::MakeStudyLayout(m.study));
  return m;
}

absl::StatusOr<SettingResult> RunSetting(const v1::Study& base, const std::string& source,
                                         const Setting& setting, const RecheckModel& recheck) {
  MBOPT_ASSIGN_OR_RETURN(spec::Study study, StudyWith(base, source, setting.analysis, setting.optimizer));
  MBOPT_ASSIGN_OR_RETURN(local_run::LocalRunResult run, local_run::RunStudyLocally(study));
  SettingResult r;
  r.setting = setting;
  r.end = slp::RunStateName(run.outcome.state);
  r.objective = run.outcome.objective;
  r.max_violation = run.outcome.max_violation;
  r.analyses = run.outcome.analyses;
  r.wall_seconds = run.wall_seconds;
  r.design_scaled = run.design_scaled;
  MBOPT_ASSIGN_OR_RETURN(engine::StudyEvaluation check,
                         local_run::EvaluateDesign(recheck.study, recheck.layout, run.outcome.design));
  r.recheck_ok = check.ok();
  if (check.ok()) {
    r.true_objective = check.values->objective;
    r.true_max_violation = check.values->max_violation;
  } else {
    r.recheck_failure = check.failure.reason;
  }
  return r;
}

}  // namespace mbopt::accuracy
