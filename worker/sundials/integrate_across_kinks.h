// Integrates to each output instant in turn, stopping at every kink of the
// inputs (a bump's edge, a delayed wheel's start) and restarting there:
// across a kink the right-hand side is not smooth, and a step over it would
// cost error-test failures or miss it. `at_instant(t, y)` sees the state at
// each instant and returns a failure, or ok to go on. Returns the first
// failure (the integrator's or at_instant's), ok if none.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/status.h"
#include "spec/analysis_outcome.h"
#include "worker/sundials/cvodes_integrator.h"
#include "worker/sundials/integrator_failure.h"

namespace mbopt::sundials {

inline spec::AnalysisFailure IntegrateAcrossKinks(
    CvodesIntegrator& integrator, const std::vector<double>& kinks_s,
    const std::vector<double>& instants_s, Eigen::VectorXd* y,
    const std::function<spec::AnalysisFailure(double t, const Eigen::VectorXd& y)>& at_instant) {
  spec::AnalysisFailure failure;
  auto check = [&](const absl::Status& status) {
    if (!status.ok() && failure.ok()) failure = IntegratorFailure(status, std::string(status.message()));
    return status.ok();
  };
  size_t next_kink = 0;
  if (next_kink < kinks_s.size()) check(integrator.SetStopTime(kinks_s[next_kink]));
  for (size_t i = 0; failure.ok() && i < instants_s.size(); ++i) {
    const double t = instants_s[i];
    while (failure.ok() && next_kink < kinks_s.size() && kinks_s[next_kink] <= t) {
      const double kink = kinks_s[next_kink++];
      if (!check(integrator.IntegrateTo(kink, y)) || !check(integrator.Restart(kink, *y))) break;
      if (next_kink < kinks_s.size()) check(integrator.SetStopTime(kinks_s[next_kink]));
    }
    if (!failure.ok() || !check(integrator.IntegrateTo(t, y))) break;
    failure = at_instant(t, *y);
  }
  return failure;
}

}  // namespace mbopt::sundials
