// Forward sensitivities of a Model Exchange FMU's outputs with respect to
// some of its parameters, from the FMU's directional derivatives (FMI 2.0
// fmi2GetDirectionalDerivative, FMI 3.0 fmi3GetDirectionalDerivative):
// CVODES integrates s_k = dx/dp_k along the states, with
//
//     s_k' = (df/dx) s_k + df/dp_k,   s_k(t0) = dx(t0)/dp_k,
//
// the right-hand side one directional derivative of the state derivatives
// with the states and p_k known, seeded with s_k and 1; s_k(t0) one of the
// states with p_k known, asked in initialization mode. An output that is a
// state has s_k as its derivative; any other output is one more directional
// derivative at each output time.
//
// What mbopt requires (SensitivitiesUnavailable says which is missing):
// Model Exchange; the FMU declares providesDirectionalDerivative (2.0) or
// providesDirectionalDerivatives (3.0) on <ModelExchange> and its binary
// exports the function; it has no event indicators (the sensitivities jump
// at events in ways the FMU does not report); every parameter differentiated
// is a Real (Float64) parameter of variability `tunable`, since it is passed
// as a known while the model runs, which the standard allows only for what
// may change then. A time event met during the run ends the sensitivities
// (`unavailable` says so) while the values are still reported.
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "worker/fmu/fmu.h"
#include "worker/fmu/simulation.h"

namespace mbopt::fmu {

// "" when `fmu` gives sensitivities with respect to the named parameters;
// else why not, naming the FMU, the flag or the parameter.
std::string SensitivitiesUnavailable(const Fmu& fmu, const std::vector<std::string>& parameter_names);

struct SensitivityResult {
  RunResult run;
  // [k][output][instant]: d output / d options.parameters[parameters[k]];
  // empty when `unavailable` says why (run's values still count).
  std::vector<std::vector<std::vector<double>>> output_derivatives;
  std::string unavailable;
};

// Simulate (simulation.h) with the derivatives of the outputs with respect
// to options.parameters[parameters[k]] for each k. A request Simulate
// refuses, or one SensitivitiesUnavailable refuses, is InvalidArgument.
absl::StatusOr<SensitivityResult> SimulateWithSensitivities(const Fmu& fmu, const RunOptions& options,
                                                            const std::vector<int>& parameters);

}  // namespace mbopt::fmu
