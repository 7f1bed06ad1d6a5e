// The two formulations of flexible links on the elastic four-bar
// (docs/accuracy.md, "Flexible-link formulations"): peak stress per link
// and CPU per analysis, floating frame against co-rotational, at the
// report's optimum and at the floating-frame model's own optimum.
#pragma once

#include <string>

#include "absl/status/statusor.h"

namespace mbopt::accuracy {

// The section's Markdown; `study_file` is the elastic four-bar study.
absl::StatusOr<std::string> FormulationComparisonMarkdown(const std::string& study_file);

}  // namespace mbopt::accuracy
