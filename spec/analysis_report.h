// What one analysis of a scene returns: how it ended, the formulation the
// engine chose, the requested outputs on the time grid, and its counters.
// Produced by the engine (worker/engine/analysis.h) and by the solvers it
// dispatches to, which is why it lives below both: the solvers fill it, the
// engine only picks which solver runs.
#pragma once

#include <string>
#include <vector>

#include "spec/analysis_outcome.h"

namespace mbopt::spec {

enum class Formulation {
  kKinematic,      // driven linkage, positions only: no time integration
  kKinetostatic,   // driven rigid linkage + inertia loads: no time integration
  kDynamic,        // free degrees of freedom integrated in time (CVODES)
  kElastodynamic,  // beam-element links on the driven motion (CVODES, stiff)
  kStatic,         // static equilibrium at each instant (KINSOL): no inertia, no damping
  kExternal,       // an external simulation code through a declared driver (worker/external)
};
const char* FormulationName(Formulation f);

// Values of one output: one or more series (a stress output has one per
// node), each with one value per grid instant (a scalar output such as mass
// has one series of one value).
struct OutputValues {
  std::string name;
  std::vector<std::string> series_labels;   // e.g. "node 3"; one per series
  std::vector<std::vector<double>> series;  // [series][instant], SI
};

struct AnalysisReport {
  AnalysisFailure failure;           // ok, or the kind and a reason saying where
  Formulation formulation = Formulation::kKinematic;
  std::vector<double> times_s;       // the grid instants
  std::vector<OutputValues> outputs; // same order as scene.outputs; empty when failed
  AnalysisCounters counters;

  bool ok() const { return failure.ok(); }
  // Marks the analysis failed; its outputs are dropped (partial series would
  // look like results).
  void Fail(FailureKind kind, std::string reason) {
    failure = AnalysisFailure::Of(kind, std::move(reason));
    outputs.clear();
  }
};

}  // namespace mbopt::spec
