// How one analysis ended, in one vocabulary from the engine to the user: the
// engine reports it, the worker sends it, the server logs and replays it, and
// `mbopt results` and the report page show it. The kind is for programs
// (counting failures by cause, deciding what a failure means); the reason is
// for people and says where (time, joint, link, element, output).
//
// Also the one set of per-analysis counters, with the same meaning on every
// side: they prove what an analysis computed (a kinematic analysis takes no
// time steps; an undeclared effect is never evaluated).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace mbopt::spec {

enum class FailureKind {
  kNone = 0,        // the analysis succeeded
  kInvalidModel,    // the model cannot be built at this design: a parameter out of its physical
                    // range (a negative stiffness, a link too short to reach), an output that does
                    // not fit the model
  kAssembly,        // the mechanism cannot be assembled or locks up: a loop that cannot close, a
                    // singular position, a driver that would tear a loop apart
  kIntegrator,      // the time integrator gave up: error-test or convergence failures, its step
                    // budget, a singular Newton matrix
  kTimeLimit,       // the analysis ran past its wall-time limit
  kNonFiniteValue,  // an output, a study value or an equation came out NaN or infinite
  kModelValidity,   // the design left the model's range of validity (a link compressed past its
                    // Euler load): the numbers would be meaningless
  kService,         // the service could not get the analysis done: every attempt's worker was
                    // lost or its lease expired, or the worker's result did not fit the task
  kInjected,        // a failure injected by a test or a fault-injection run
  kCancelled,       // stopped on request before it ended: its job was cancelled
  kUnclassified,    // logged before failure kinds existed
};

// Stable lower-case names ("assembly", "integrator", ...), used in the job
// database, JSON output and the report page; "ok" for kNone.
const char* FailureKindName(FailureKind kind);
std::optional<FailureKind> ParseFailureKind(std::string_view name);

// The end of one analysis: ok, or a failure of a kind with its reason.
struct AnalysisFailure {
  FailureKind kind = FailureKind::kNone;
  std::string reason;  // empty when ok

  bool ok() const { return kind == FailureKind::kNone; }
  static AnalysisFailure Ok() { return {}; }
  static AnalysisFailure Of(FailureKind kind, std::string reason) { return {kind, std::move(reason)}; }
};

// Counters of one analysis (sums over its instants and integrations).
struct AnalysisCounters {
  std::int64_t time_steps = 0;
  std::int64_t rhs_evaluations = 0;        // right-hand sides (ODE) or residuals (DAE)
  std::int64_t jacobian_evaluations = 0;
  std::int64_t newton_iterations = 0;
  std::int64_t position_solves = 0;        // kinematic Newton solves (one per instant)
  double wall_seconds = 0.0;               // the analysis' own running time

  AnalysisCounters& operator+=(const AnalysisCounters& other);
};

}  // namespace mbopt::spec
