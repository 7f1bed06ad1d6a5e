// What the engine's two SUNDIALS integrations (forward_dynamics.cc on
// IDAS, explicit_dynamics.cc on ERKStep) set up alike, on the owners of
// worker/sundials/sundials_handles.h: the context with the run's serial
// vectors, whose failure to allocate is an integrator failure; the check
// of every call's return flag, with SUNDIALS' own message kept for the
// failure's reason rather than printed; and the validity bounds' check at
// the start, before their root finding watches for crossings.
#pragma once

#include <nvector/nvector_serial.h>

#include <initializer_list>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "absl/strings/str_format.h"
#include "spec/analysis_outcome.h"
#include "worker/multibody/constrained_system.h"
#include "worker/sundials/sundials_handles.h"

namespace mbopt::multibody {

// Creates `*context` and, in it, each of `vectors` with `length` entries
// (their values unset). An integrator failure when any cannot be created.
inline spec::AnalysisFailure CreateContextAndVectors(sunindextype length, sundials::Context* context,
                                                     std::initializer_list<sundials::Vector*> vectors) {
  *context = sundials::MakeContext();
  if (!*context) return spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, "SUNContext_Create failed");
  for (sundials::Vector* vector : vectors) {
    vector->reset(N_VNew_Serial(length, context->get()));
    if (!*vector) return spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, "SUNDIALS allocation failed");
  }
  return spec::AnalysisFailure::Ok();
}

// The return flags of one run's SUNDIALS calls. A negative flag fails the
// call; its message names the call and the flag, then what SUNDIALS said
// (sundials::CaptureMessage writes that into message_sink(): pass it to the
// integrator's SetErrHandlerFn). Positive flags are warnings and pass.
class SundialsCalls {
 public:
  // Whether `call` returned `flag` without failing.
  bool operator()(int flag, const char* call) {
    if (flag >= 0) return true;
    message_ = absl::StrFormat("%s failed (%d)%s%s", call, flag, message_.empty() ? "" : ": ", message_);
    return false;
  }
  void* message_sink() { return &message_; }
  // The latest failure's message, or SUNDIALS' latest message.
  const std::string& message() const { return message_; }
  spec::AnalysisFailure Failure() const { return spec::AnalysisFailure::Of(spec::FailureKind::kIntegrator, message_); }

 private:
  std::string message_;
};

// A start outside a validity bound is a model failure at t0, named by the
// first bound it violates (a NaN bound counts as violated).
inline spec::AnalysisFailure ValidityBoundsHoldAtStart(const ConstrainedSystem& system, double t0,
                                                       const Eigen::VectorXd& q0, const Eigen::VectorXd& v0) {
  const int num_bounds = system.num_validity_bounds();
  if (num_bounds == 0) return spec::AnalysisFailure::Ok();
  std::vector<double> g(static_cast<std::size_t>(num_bounds));
  system.ValidityBounds(t0, q0, v0, g.data());
  for (int k = 0; k < num_bounds; ++k) {
    if (!(g[static_cast<std::size_t>(k)] >= 0.0)) {
      return spec::AnalysisFailure::Of(spec::FailureKind::kModelValidity, system.BoundReason(k, t0, q0, v0));
    }
  }
  return spec::AnalysisFailure::Ok();
}

}  // namespace mbopt::multibody
