// NLopt's SLSQP and MMA run on a study as a user would set them up: the same
// analyses (local_run::EvaluateDesign), the same scaled variables and bounds,
// forward-difference gradients with the SLP core's step rule (CountedStudy),
// constraints normalized (g - c) / scale <= 0, and a min-max objective in
// the bound formulation (minimize b subject to f_i / |F0| - b <= 0) so the
// peer sees a smooth problem. The objective is divided by |F(x0)|.
//
// NLopt asks for the gradient with every function value, line-search points
// included, so each evaluation costs 1 + n analyses here. The run stops when
// the next request would exceed the analysis cap.
#pragma once

#include <cstdint>

#include "absl/status/statusor.h"
#include "bench/compare/method_run.h"
#include "server/slp/options.h"
#include "tests/testing/local_run/local_run.h"
#include "spec/study.h"

namespace mbopt::compare {

enum class PeerAlgorithm { kSlsqp, kMma };
const char* PeerAlgorithmName(PeerAlgorithm algorithm);

struct PeerOptions {
  std::int64_t max_analyses = 2000;
  // NLopt's own stopping tests (relative change of the objective / of x).
  double ftol_rel = 1e-6;
  double xtol_rel = 1e-6;
  // Tolerance on each normalized constraint. NLopt returns the best point
  // it saw that meets every constraint within it; with 0, finite-difference
  // noise of 1e-12 at an active constraint makes NLopt fall back to an
  // early, strictly feasible design.
  double constraint_tolerance = 1e-6;
};

// `fd_options` supplies the finite-difference step rule (forward is forced).
absl::StatusOr<MethodRun> RunNloptPeer(const spec::Study& study, PeerAlgorithm algorithm,
                                       const slp::SlpOptions& fd_options,
                                       const PeerOptions& options);

}  // namespace mbopt::compare
