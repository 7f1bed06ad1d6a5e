// The study's values (objective terms, constraint values, F, worst row) of
// one analysis: spec::ComputeStudyValues applied to an engine report. Used by
// the worker and by `mbopt-worker eval`; depends on no solver.
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "spec/layout.h"
#include "spec/study.h"
#include "spec/analysis_report.h"
#include "spec/responses.h"

namespace mbopt::engine {

// FailedPrecondition if the analysis failed (its reason in the message);
// InvalidArgument if its outputs do not have the layout's shape. An output
// may report more series than the layout uses (e.g. a stress series at every
// node, pinned ends included); the layout's series are then picked by their
// labels (spec::OutputShapeOf). The study's responses are computed from the
// outputs and `parameter_values_si`, the analysis' SI parameter values
// (Study::ParameterValuesAt).
// Every signal of one analysis, SI: the outputs of every load case (the
// layout's series, picked by label where the engine reports more), then the
// study's responses. `signals` points into the report and into this object,
// which is filled in place and not moved.
struct StudySignals {
  std::vector<const spec::Series*> signals;
  std::vector<spec::Series> selected;   // per output, when picked by label
  std::vector<spec::Series> responses;
};
absl::Status BuildStudySignals(const spec::Study& study, const spec::StudyLayout& layout,
                               const spec::AnalysisReport& report, const std::vector<double>& parameter_values_si,
                               StudySignals* out);

absl::StatusOr<spec::StudyValues> ComputeStudyValues(const spec::Study& study,
                                                     const spec::StudyLayout& layout,
                                                     const spec::AnalysisReport& report,
                                                     const std::vector<double>& parameter_values_si);

}  // namespace mbopt::engine
