// One simulation of an FMI 2.0 or 3.0 FMU: parameters set by name, the model run
// from its start time to the last output time, the requested variables
// sampled on the output time grid.
//
// Model Exchange: the FMU's continuous states are integrated with CVODES
// (BDF, dense Newton), state events are found by CVODES' root finding on the
// FMU's event indicators, time events stop the integrator exactly at the
// FMU's nextEventTime, and after every event the FMU's discrete states are
// iterated to a fixed point (fmi2NewDiscreteStates / fmi3UpdateDiscreteStates) and CVODES restarts from
// the new states. Outputs between steps are read from the FMU at states
// interpolated by CVODES; an output at an event's time is the value just
// before the event (the left limit).
//
// Co-Simulation: fmi2DoStep / fmi3DoStep at one fixed communication step (the run's, else
// the model description's DefaultExperiment stepSize), from the start time.
// Every output time must be a whole number of steps after the start (to
// 1e-9 of a step); the outputs are the FMU's values at those communication
// points, never interpolated.
//
// Bad requests (unknown names, a variable that is not a parameter, a grid
// the steps do not meet) are an InvalidArgument status before the FMU is
// instantiated, listing what exists. What goes wrong while the model runs
// (the FMU returns an error, the integrator gives up, the FMU ends the
// simulation early) is a RunResult with an outcome and a reason that carries
// the FMU's own last log messages.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "worker/fmu/fmu.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::fmu {

struct RunOptions {
  double start_time_s = 0.0;
  // Values of Real parameters (causality parameter, variability fixed or
  // tunable), by variable name, set before initialization.
  std::vector<std::pair<std::string, double>> parameters;
  // Real variables to sample, by name, at each of output_times_s
  // (non-decreasing, none before start_time_s; the last is the stop time).
  std::vector<std::string> outputs;
  std::vector<double> output_times_s;

  // Model Exchange.
  double relative_tolerance = 1e-8;
  double absolute_tolerance = 1e-10;
  std::int64_t max_steps = 1000000;         // CVODES steps over the whole run
  int max_events = 100000;                  // state and time events over the whole run
  int max_event_iterations = 1000;          // discrete-state updates at one event

  // The analysis' deadline and cancel flag, checked after every integrator
  // step and every DoStep; null: none. A call into the FMU that never
  // returns is not interrupted (the service's lease covers that).
  const budget::AnalysisBudget* budget = nullptr;

  // Co-Simulation: the communication step; unset: DefaultExperiment stepSize.
  std::optional<double> communication_step_s;
};

enum class RunOutcome {
  kOk,
  kModelError,         // an FMI call returned an error or fatal status (or discard where no retry exists)
  kIntegratorFailure,  // CVODES gave up (step size, error test, convergence, too many steps or events)
  kTerminated,         // the FMU ended the simulation before the last output time
  kTimeLimit,          // the budget's deadline passed
  kCancelled,          // the budget's cancel flag went up
};

const char* RunOutcomeName(RunOutcome outcome);

struct RunResult {
  RunOutcome outcome = RunOutcome::kOk;
  std::string reason;  // empty when kOk
  // values[k][i]: output k at output_times_s[i]; complete only when kOk.
  std::vector<std::vector<double>> values;
  std::vector<double> state_event_times_s;  // Model Exchange: root-finding events, in time order
  std::vector<double> time_event_times_s;   // Model Exchange: nextEventTime events, in time order
  std::int64_t integrator_steps = 0;        // CVODES steps, or DoStep calls
};

absl::StatusOr<RunResult> Simulate(const Fmu& fmu, const RunOptions& options);

}  // namespace mbopt::fmu
