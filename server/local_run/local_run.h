// Runs a study's optimization to its end in this process, without a server or
// workers: the study's layout and problem (spec/layout.h,
// server/jobs/problem_from_study.h), the SLP core with the CLP LP solver, and
// every requested analysis computed here, one after another, by
// EvaluateDesign (evaluate_design.h).
//
// For tests, benchmarks and tools that want the method's answer for a study
// file without the service. It owns nothing beyond one call: no threads, no
// files, no clock other than the wall time it reports. The optimizer is built
// as the server's jobs::Job builds it (same problem, settings and LP solver),
// so with the same analysis results a local run follows the same designs as
// a service run of the study.
//
// Failures of an analysis (engine kFailed, non-finite values, or a failure
// injected by the caller) are handed to the optimizer as
// AnalysisOutcome::kFailed; the optimizer reacts (retries a perturbation,
// rejects a trial, or ends kFailed when x0 cannot be analysed). They are part
// of the result, never an error status.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/slp/options.h"
#include "server/slp/run_to_completion.h"
#include "server/slp/slp_optimizer.h"
#include "spec/layout.h"
#include "spec/study.h"
#include "worker/engine/analysis.h"

namespace mbopt::local_run {

struct LocalRunOptions {
  // Replaces the study's optimizer settings (SlpOptionsFromStudy) entirely.
  std::optional<slp::SlpOptions> slp_override;
  // Called with every cycle record as soon as the optimizer emits it.
  std::function<void(const slp::CycleRecord&)> on_record;
  // Called before each analysis; a returned reason makes that analysis fail
  // with it, without running the engine (fault injection for tests).
  std::function<std::optional<std::string>(const slp::AnalysisRequest&)> inject_failure;
  // Guard against a run that never ends: ResourceExhausted past this.
  std::int64_t max_analyses = 100'000;
};

struct LocalRunResult {
  // The optimizer's end: state, every record and submitted result, the
  // final design (scaled), F, maxg, cycles, analyses.
  slp::RunOutcome outcome;
  std::string end_reason;  // the optimizer's, for kStalled / kFailed
  spec::StudyLayout layout;
  // The final design per variable: scaled (as outcome.design), in the
  // parameter's unit as the scene file writes it (scale * x), and in SI.
  std::vector<double> design_scaled;
  std::vector<double> design_physical;
  std::vector<double> design_si;
  // Sum of the counters of every analysis run (wall_seconds: their sum).
  engine::AnalysisCounters total_counters;
  std::int64_t analyses_run = 0;     // engine analyses (injected failures excluded)
  std::int64_t analyses_failed = 0;  // results handed over as kFailed, injected included
  double wall_seconds = 0;           // of the whole call
};

// InvalidArgument when the study cannot be laid out or its problem or
// settings are invalid; InvalidArgument when an analysis report does not
// have the layout's shape (an engine bug, not a numerical outcome);
// ResourceExhausted past options.max_analyses. Otherwise the run's result,
// whatever state it ended in.
absl::StatusOr<LocalRunResult> RunStudyLocally(const spec::Study& study,
                                               const LocalRunOptions& options = {});

}  // namespace mbopt::local_run
