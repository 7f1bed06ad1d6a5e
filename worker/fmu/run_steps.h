// Steps of a simulation shared by the two interface types (simulation.cc)
// and the Model Exchange loop (model_exchange.cc). Internal to worker/fmu.
#pragma once

#include <chrono>
#include <vector>

#include "worker/fmu/fmi2_instance.h"
#include "worker/fmu/simulation.h"

namespace mbopt::fmu::internal {

// A request checked against the model description, as value references.
struct CheckedRun {
  std::vector<fmi2ValueReference> output_references;
  std::vector<fmi2ValueReference> parameter_references;
  std::vector<double> parameter_values;
  double stop_time_s = 0.0;
};

// The run's wall-time limit (RunOptions::max_wall_seconds).
class WallClock {
 public:
  explicit WallClock(double max_seconds) : max_seconds_(max_seconds), start_(std::chrono::steady_clock::now()) {}
  // False (and `result` failed with kTimeLimit) once the limit is passed.
  bool Within(double time_s, RunResult* result) const;

 private:
  double max_seconds_;
  std::chrono::steady_clock::time_point start_;
};

// Marks `result` failed with `outcome` and `reason`; returns false.
bool Fail(RunResult* result, RunOutcome outcome, std::string reason);

// fmi2SetupExperiment, the parameters, and initialization mode entered and
// left. False (and `result` failed) when the FMU refuses any of it.
bool Initialize(Fmi2Instance& instance, const RunOptions& options, const CheckedRun& run, double tolerance,
                RunResult* result);

// Reads the outputs into result->values[.][time_index].
bool ReadOutputs(Fmi2Instance& instance, const CheckedRun& run, int time_index, double time_s, RunResult* result);

RunResult RunModelExchange(const Fmu& fmu, Fmi2Instance& instance, const RunOptions& options, const CheckedRun& run);

}  // namespace mbopt::fmu::internal
