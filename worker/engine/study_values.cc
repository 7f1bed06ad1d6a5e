#include "worker/engine/study_values.h"

#include "absl/strings/str_cat.h"

namespace mbopt::engine {

absl::StatusOr<spec::StudyValues> ComputeStudyValues(const spec::Study& study,
                                                     const spec::StudyLayout& layout,
                                                     const AnalysisReport& report) {
  if (report.status != AnalysisStatus::kOk) {
    return absl::FailedPreconditionError(absl::StrCat("analysis failed: ", report.failure_reason));
  }
  std::vector<const std::vector<std::vector<double>>*> series;
  series.reserve(report.outputs.size());
  for (const OutputValues& output : report.outputs) series.push_back(&output.series);
  return spec::ComputeStudyValues(study, layout, series);
}

}  // namespace mbopt::engine
