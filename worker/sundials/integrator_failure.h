// The failure kind of a SUNDIALS wrapper's status: its analysis budget's
// deadline is a time-limit failure, its cancel flag a cancelled analysis,
// anything else the integrator giving up.
#pragma once

#include <string>

#include "absl/status/status.h"
#include "spec/analysis_outcome.h"

namespace mbopt::sundials {

inline spec::AnalysisFailure IntegratorFailure(const absl::Status& status, std::string reason) {
  spec::FailureKind kind = spec::FailureKind::kIntegrator;
  if (absl::IsDeadlineExceeded(status)) kind = spec::FailureKind::kTimeLimit;
  if (absl::IsCancelled(status)) kind = spec::FailureKind::kCancelled;
  return spec::AnalysisFailure::Of(kind, std::move(reason));
}

}  // namespace mbopt::sundials
