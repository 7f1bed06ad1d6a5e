// Steps of a simulation shared by the two interface types (simulation.cc)
// and the Model Exchange loop (model_exchange.cc). Internal to worker/fmu.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "worker/fmu/fmu.h"
#include "worker/fmu/model_instance.h"
#include "worker/fmu/simulation.h"

namespace mbopt::fmu::internal {

// A request checked against the model description, as value references.
struct CheckedRun {
  std::vector<ValueReference> output_references;
  std::vector<ValueReference> parameter_references;
  std::vector<double> parameter_values;
  double stop_time_s = 0.0;
};

// Forward sensitivities of a Model Exchange run with respect to some of
// its parameters (sensitivities.h): what the driver needs, and what it
// fills in.
struct SensitivityRun {
  std::vector<ValueReference> parameter_references;  // one per sensitivity
  std::vector<ValueReference> state_references;      // in the FMU's state order
  std::vector<ValueReference> derivative_references;
  // Per output: the index of the state it is (its derivative is the
  // state's sensitivity), or -1 (asked of the FMU).
  std::vector<int> output_state_index;

  // [k][output][instant]; complete when `unavailable` is empty.
  std::vector<std::vector<std::vector<double>>> output_derivatives;
  // Why the run ended without sensitivities although its values are fine.
  std::string unavailable;
};

// The request checked against the model description (simulation.h says
// what is refused).
absl::StatusOr<CheckedRun> CheckRequest(const Fmu& fmu, const RunOptions& options);

// A new instance, or null with `result` failed naming the FMU's
// instantiate function and its messages.
std::unique_ptr<ModelInstance> Instantiate(const Fmu& fmu, RunResult* result);

// The run's budget (RunOptions::budget): false, and `result` failed with
// kTimeLimit or kCancelled, once it is spent at simulated time `time_s`.
bool WithinBudget(const RunOptions& options, double time_s, RunResult* result);

// Marks `result` failed with `outcome` and `reason`; returns false.
bool Fail(RunResult* result, RunOutcome outcome, std::string reason);

// The experiment set up, the parameters set, and initialization mode
// entered and left. False (and `result` failed) when the FMU refuses any of it.
// `in_initialization_mode` (if any) runs between entering and leaving it;
// false from it fails the run as it says.
bool Initialize(ModelInstance& instance, const RunOptions& options, const CheckedRun& run, double tolerance,
                RunResult* result, const std::function<bool()>& in_initialization_mode = nullptr);

// Reads the outputs into result->values[.][time_index].
bool ReadOutputs(ModelInstance& instance, const CheckedRun& run, int time_index, double time_s, RunResult* result);

// With `sensitivities` (null: none), CVODES integrates the forward
// sensitivities too and fills in its output derivatives.
RunResult RunModelExchange(const Fmu& fmu, ModelInstance& instance, const RunOptions& options, const CheckedRun& run,
                           SensitivityRun* sensitivities = nullptr);

}  // namespace mbopt::fmu::internal
