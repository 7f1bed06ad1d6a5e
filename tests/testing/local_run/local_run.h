// Runs a study's optimization to its end in this process, without a server or
// workers: a jobs::Job (the one driver of the SLP core, with the service's
// intake, normalization and replay code) with the CLP LP solver and an
// InProcessEvaluator (the engine's one study evaluation). So with the same
// analyses a local run follows the same designs as a service run of the
// study, bit for bit.
//
// For tests, benchmarks and tools that want the method's answer for a study
// file without the service. It owns nothing beyond one call: no threads, no
// files, no clock other than the wall time it reports.
//
// Failures of an analysis (engine failures, non-finite values, or a failure
// injected by the caller) are handed to the optimizer as failed analyses;
// the optimizer reacts (retries a perturbation, rejects a trial, or ends
// kFailed when x0 cannot be analysed). They are part of the result, never
// an error status.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/statusor.h"
#include "server/jobs/analysis_record.h"
#include "server/slp/options.h"
#include "server/slp/slp_optimizer.h"
#include "spec/analysis_outcome.h"
#include "spec/layout.h"
#include "spec/study.h"
#include "worker/engine/evaluate_study.h"
#include "tests/testing/local_run/in_process_evaluator.h"

namespace mbopt::local_run {

struct LocalRunOptions {
  // Replaces the study's optimizer settings (SlpOptionsFromStudy) entirely.
  std::optional<slp::SlpOptions> slp_override;
  // Called with every cycle record as soon as the optimizer emits it.
  std::function<void(const slp::CycleRecord&)> on_record;
  // Fault injection for tests (InProcessEvaluator::FailureInjector).
  InProcessEvaluator::FailureInjector inject_failure;
  // Guard against a run that never ends: ResourceExhausted past this.
  std::int64_t max_analyses = 100'000;
};

// The optimizer's end.
struct RunOutcome {
  slp::RunState state = slp::RunState::kRunning;
  std::vector<slp::CycleRecord> records;
  std::vector<jobs::AnalysisRecord> results;  // every record applied, in order
  Eigen::VectorXd design;                     // scaled
  double objective = 0;
  double max_violation = 0;
  int cycles = 0;
  std::int64_t analyses = 0;
};

struct LocalRunResult {
  RunOutcome outcome;
  std::string end_reason;  // the optimizer's, for kStalled / kFailed
  std::vector<std::string> result_notes;  // the optimizer's notes on the result
  spec::StudyLayout layout;
  // The final design per variable: scaled (as outcome.design), in the
  // parameter's unit as the scene file writes it (scale * x), and in SI.
  std::vector<double> design_scaled;
  std::vector<double> design_physical;
  std::vector<double> design_si;
  // Sum of the counters of every analysis run (wall_seconds: their sum).
  spec::AnalysisCounters total_counters;
  std::int64_t analyses_run = 0;     // engine analyses (injected failures excluded)
  std::int64_t analyses_failed = 0;  // records applied as failed, injected included
  std::map<spec::FailureKind, std::int64_t> failures_by_kind;
  double wall_seconds = 0;           // of the whole call
};

// The engine's one study evaluation (engine::EvaluateStudy) of a design
// given as the optimizer's scaled vector: for tools that re-check a design,
// e.g. on a finer time grid (a study whose scene has a different grid, and
// the layout made from it). On the process' clock, as a worker runs it.
absl::StatusOr<engine::StudyEvaluation> EvaluateDesign(const spec::Study& study, const spec::StudyLayout& layout,
                                                       const Eigen::VectorXd& x_scaled, bool want_gradients = false);

// InvalidArgument when the study cannot be laid out or its problem or
// settings are invalid; ResourceExhausted past options.max_analyses.
// Otherwise the run's result, whatever state it ended in.
absl::StatusOr<LocalRunResult> RunStudyLocally(const spec::Study& study, const LocalRunOptions& options = {});

}  // namespace mbopt::local_run
