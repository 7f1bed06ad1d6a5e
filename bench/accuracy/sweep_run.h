// One point of the accuracy sweep: the study with one setting applied,
// optimized to its end in this process (local_run::RunStudyLocally), and the
// design it found re-analysed on the fine re-check model.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "bench/accuracy/sweep_plan.h"
#include "mbopt/v1/study.pb.h"
#include "spec/layout.h"
#include "spec/study.h"

namespace mbopt::accuracy {

// The model every found design is re-checked on.
struct RecheckModel {
  spec::Study study;
  spec::StudyLayout layout;
};

struct SettingResult {
  Setting setting;
  std::string end;             // the optimizer's end state
  double objective = 0;        // F at the found design, as the run saw it
  double max_violation = 0;    // maxg there, as the run saw it
  bool recheck_ok = false;
  std::string recheck_failure;
  double true_objective = 0;      // F of the found design on the re-check model
  double true_max_violation = 0;  // maxg there (normalized, > 0 violated)
  std::int64_t analyses = 0;
  double wall_seconds = 0;        // the whole optimization run
  std::vector<double> design_scaled;
};

// `base` is the study file with its scene inlined (spec::io::ReadStudyProto).
absl::StatusOr<spec::Study> StudyWith(const v1::Study& base, const std::string& source,
                                      const v1::AnalysisOverrides& analysis,
                                      const v1::OptimizerOptions& optimizer);

absl::StatusOr<RecheckModel> MakeRecheckModel(const v1::Study& base, const std::string& source,
                                              const v1::AnalysisOverrides& recheck);

// InvalidArgument / ResourceExhausted from the run; a failed re-check
// analysis is data (recheck_ok false).
absl::StatusOr<SettingResult> RunSetting(const v1::Study& base, const std::string& source,
                                         const Setting& setting, const RecheckModel& recheck);

}  // namespace mbopt::accuracy
