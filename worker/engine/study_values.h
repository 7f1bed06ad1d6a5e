// The study's values (objective terms, constraint values, F, worst row) of
// one analysis: spec::ComputeStudyValues applied to an engine report. Used by
// the worker and by `mbopt-worker eval`; depends on no solver.
#pragma once

#include <vector>

#include "absl/status/statusor.h"
#include "spec/layout.h"
#include "spec/study.h"
#include "spec/analysis_report.h"

namespace mbopt::engine {

// FailedPrecondition if the analysis failed (its reason in the message);
// InvalidArgument if its outputs do not have the layout's shape. An output
// may report more series than the layout uses (e.g. a stress series at every
// node, pinned ends included); the layout's series are then picked by their
// labels (spec::OutputShapeOf). The study's responses are computed from the
// outputs and `parameter_values_si`, the analysis' SI parameter values
// (Study::ParameterValuesAt).
absl::StatusOr<spec::StudyValues> ComputeStudyValues(const spec::Study& study,
                                                     const spec::StudyLayout& layout,
                                                     const spec::AnalysisReport& report,
                                                     const std::vector<double>& parameter_values_si);

}  // namespace mbopt::engine
