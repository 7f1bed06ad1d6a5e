// The analysis engine's entry point: one simulation of a scene at one set of
// parameter values. Pure: no gRPC, no SQLite, no threads. The engine picks the
// cheapest formulation the scene allows and computes only the requested
// outputs. Failure is data: a failed analysis returns status kFailed with a
// reason, never a crash and never a silent wrong value.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "spec/scene.h"

namespace mbopt::engine {

enum class Formulation {
  kKinematic,      // driven linkage, positions only: no time integration
  kKinetostatic,   // driven rigid linkage + inertia loads: no time integration
  kDynamic,        // free degrees of freedom integrated in time (CVODES)
  kElastodynamic,  // beam-element links on the driven motion (CVODES, stiff)
};
const char* FormulationName(Formulation f);

enum class AnalysisStatus { kOk, kFailed };

struct AnalysisCounters {
  std::int64_t time_steps = 0;
  std::int64_t rhs_evaluations = 0;
  std::int64_t jacobian_evaluations = 0;
  std::int64_t newton_iterations = 0;
  std::int64_t position_solves = 0;  // kinematic Newton solves (one per instant)
  double wall_seconds = 0.0;
};

// Values of one output: one or more series (a stress output has one per
// node), each with one value per grid instant (a scalar output such as mass
// has one series of one value).
struct OutputValues {
  std::string name;
  std::vector<std::string> series_labels;   // e.g. "node 3"; one per series
  std::vector<std::vector<double>> series;  // [series][instant], SI
};

struct AnalysisReport {
  AnalysisStatus status = AnalysisStatus::kOk;
  std::string failure_reason;  // says where: time, joint, element, ...
  Formulation formulation = Formulation::kKinematic;
  std::vector<double> times_s;       // the grid instants
  std::vector<OutputValues> outputs; // same order as scene.outputs
  AnalysisCounters counters;
};

// Runs one analysis. `parameter_values_si` has one SI value per scene
// parameter.
AnalysisReport Analyze(const spec::Scene& scene,
                       const std::vector<double>& parameter_values_si);

}  // namespace mbopt::engine
