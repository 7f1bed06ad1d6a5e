// The failure kind of a SUNDIALS wrapper's status: its wall-time limit is a
// time-limit failure, anything else the integrator giving up.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "spec/analysis_outcome.h"

namespace mbopt::solve {

inline spec::AnalysisFailure IntegratorFailure(const absl::Status& status, std::string reason) {
  return spec::AnalysisFailure::Of(absl::IsDeadlineExceeded(status) ? spec::FailureKind::kTimeLimit
                                                                    : spec::FailureKind::kIntegrator,
                                   std::move(reason));
}

}  // namespace mbopt::solve
