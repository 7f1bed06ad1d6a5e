#include "worker/engine/study_values.h"

#include "absl/strings/str_cat.h"

namespace mbopt::engine {

absl::Status BuildStudySignals(const spec::Study& study, const spec::StudyLayout& layout,
                               const spec::AnalysisReport& report, const std::vector<double>& parameter_values_si,
                               StudySignals* out) {
  if (!report.ok()) {
    return absl::FailedPreconditionError(absl::StrCat("analysis failed: ", report.failure.reason));
  }
  if (report.outputs.size() != static_cast<size_t>(study.num_case_signals())) {
    return absl::InvalidArgumentError(absl::StrCat("analysis has ", report.outputs.size(), " outputs, the study ",
                                                   study.num_case_signals(), " (its scene's for each load case)"));
  }
  out->signals.assign(report.outputs.size(), nullptr);
  out->selected.assign(report.outputs.size(), {});
  for (size_t o = 0; o < report.outputs.size(); ++o) {
    const spec::OutputValues& output = report.outputs[o];
    const spec::OutputShape& shape = layout.outputs[o];
    if (static_cast<int>(output.series.size()) == shape.series) {
      out->signals[o] = &output.series;
      continue;
    }
    // More series than the layout uses (e.g. stress at pinned nodes, zero
    // by construction): pick the layout's series by label.
    for (const std::string& label : shape.series_labels) {
      size_t found = output.series_labels.size();
      for (size_t s = 0; s < output.series_labels.size() && s < output.series.size(); ++s) {
        if (output.series_labels[s] == label) found = s;
      }
      if (found == output.series_labels.size()) {
        return absl::InvalidArgumentError(absl::StrCat(
            "output \"", output.name, "\" has ", output.series.size(),
            " series and none labelled \"", label, "\", which the study's layout needs"));
      }
      out->selected[o].push_back(output.series[found]);
    }
    out->signals[o] = &out->selected[o];
  }
  spec::AppendResponses(study, layout, parameter_values_si, &out->responses, &out->signals);
  return absl::OkStatus();
}

absl::StatusOr<spec::StudyValues> ComputeStudyValues(const spec::Study& study,
                                                     const spec::StudyLayout& layout,
                                                     const spec::AnalysisReport& report,
                                                     const std::vector<double>& parameter_values_si) {
  StudySignals signals;
  if (absl::Status s = BuildStudySignals(study, layout, report, parameter_values_si, &signals); !s.ok()) return s;
  return spec::ComputeStudyValues(study, layout, signals.signals);
}

}  // namespace mbopt::engine
