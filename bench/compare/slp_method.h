// Our SLP method (local_run::RunStudyLocally with the study's own settings)
// as a MethodRun: candidates are the initial design and every trial point
// the method analysed, at the analysis count the optimizer reports.
#pragma once

#include "absl/status/statusor.h"
#include "bench/compare/method_run.h"
#include "spec/study.h"

namespace mbopt::compare {

absl::StatusOr<MethodRun> RunSlpMethod(const spec::Study& study);

}  // namespace mbopt::compare
