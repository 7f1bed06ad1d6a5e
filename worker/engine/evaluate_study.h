// Evaluating a study at one design point: the one place where a scaled design
// becomes scene parameter values (Study::ParameterValuesAt), the engine
// analyses the scene there (analysis.h, or study_sensitivities.h when the
// caller wants the simulator's gradients), and the study layout turns the
// outputs into the values the optimizer asked for (objective terms and
// constraint rows, spec/layout.h). The worker service translates this to and
// from its wire messages; in-process runs (tests/testing/local_run) call it
// directly; `mbopt-worker eval` prints it.
//
// Everything that can go wrong with the analysis is data: a failed
// evaluation carries the engine's failure kind and reason, and a study value
// that comes out NaN or infinite is a kNonFiniteValue failure naming the
// objective term or constraint row. Gradients are optional extras: missing or
// non-finite gradients leave `gradients` empty with the reason in
// `gradients_unavailable`, never a failed evaluation. Pure: no threads, no I/O.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "spec/analysis_report.h"
#include "spec/layout.h"
#include "spec/study.h"
#include "spec/study_gradients.h"
#include "worker/engine/external_analyzer.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::engine {

struct StudyEvaluation {
  spec::AnalysisFailure failure;  // ok, or the kind and where
  spec::Formulation formulation = spec::Formulation::kKinematic;
  spec::AnalysisCounters counters;  // of this analysis, wall time included
  // Present exactly when ok: num_objective_terms and num_constraints values,
  // every one finite.
  std::optional<spec::StudyValues> values;
  // Only when asked for and available: [term][variable] and [row][variable],
  // d(value)/d(x_scaled), every entry finite. Otherwise empty, and
  // gradients_unavailable says why.
  std::optional<spec::StudyGradients> gradients;
  std::string gradients_unavailable;

  bool ok() const { return failure.ok(); }
};

// `layout` must be MakeStudyLayout(study). InvalidArgument when the request
// does not fit the study (x_scaled of the wrong size or not finite) or the
// engine's outputs do not have the layout's shape (an engine defect, not a
// numerical outcome).
// `external` runs external scenes (external_analyzer.h).
// `budget` brings the caller's clock (for the time limit and the wall time)
// and cancel flag (engine::Analyze).
absl::StatusOr<StudyEvaluation> EvaluateStudy(const spec::Study& study, const spec::StudyLayout& layout,
                                              const std::vector<double>& x_scaled, bool want_gradients,
                                              const ExternalAnalyzer* external = nullptr,
                                              const budget::AnalysisBudget& budget = budget::AnalysisBudget());

}  // namespace mbopt::engine
