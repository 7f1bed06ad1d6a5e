// The optimizer's view of a study: the ProblemSpec (scaled variables,
// objective form, constraint rows from spec/layout.h) and the SlpOptions
// (the study's optimizer settings over the method's defaults).
#pragma once

#include "absl/status/statusor.h"
#include "server/slp/options.h"
#include "server/slp/problem.h"
#include "spec/layout.h"
#include "spec/study.h"

namespace mbopt::jobs {

// InvalidArgument (from ProblemSpec::Validate, prefixed with the study's
// file) if the result is not a valid problem, e.g. initial outside bounds.
absl::StatusOr<slp::ProblemSpec> ProblemSpecFromStudy(const spec::Study& study, const spec::StudyLayout& layout);

// InvalidArgument (from SlpOptions::Validate) for settings out of range.
// Simulator sensitivities (optimizer.sensitivity SENSITIVITY_METHOD_SIMULATOR)
// set SlpOptions::analyses_provide_gradients, for local runs and the service
// alike: their analyses return gradients where the engine has them (lumped
// scenes; the study loader already refuses the option for linkage scenes),
// and an analysis without them makes that cycle use finite differences.
absl::StatusOr<slp::SlpOptions> SlpOptionsFromStudy(const spec::Study& study);

}  // namespace mbopt::jobs
