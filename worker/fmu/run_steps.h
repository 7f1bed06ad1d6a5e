// Steps of a simulation shared by the two interface types (simulation.cc)
// and the Model Exchange loop (model_exchange.cc). Internal to worker/fmu.
#pragma once

#include <vector>

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

// The run's budget (RunOptions::budget): false, and `result` failed with
// kTimeLimit or kCancelled, once it is spent at simulated time `time_s`.
bool WithinBudget(const RunOptions& options, double time_s, RunResult* result);

// Marks `result` failed with `outcome` and `reason`; returns false.
bool Fail(RunResult* result, RunOutcome outcome, std::string reason);

// The experiment set up, the parameters set, and initialization mode
// entered and left. False (and `result` failed) when the FMU refuses any of it.
bool Initialize(ModelInstance& instance, const RunOptions& options, const CheckedRun& run, double tolerance,
                RunResult* result);

// Reads the outputs into result->values[.][time_index].
bool ReadOutputs(ModelInstance& instance, const CheckedRun& run, int time_index, double time_s, RunResult* result);

RunResult RunModelExchange(const Fmu& fmu, ModelInstance& instance, const RunOptions& options, const CheckedRun& run);

}  // namespace mbopt::fmu::internal
