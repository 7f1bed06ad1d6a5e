#include "client/study_text.h"

#include "absl/strings/str_format.h"

namespace mbopt::client {

const char* ReductionName(spec::Reduction reduction) {
  switch (reduction) {
    case spec::Reduction::kMax: return "max";
    case spec::Reduction::kMaxAbs: return "max_abs";
    case spec::Reduction::kMin: return "min";
    case spec::Reduction::kFinal: return "final";
    case spec::Reduction::kRms: return "rms";
    case spec::Reduction::kIntegral: return "integral";
    case spec::Reduction::kRange: return "range";
    case spec::Reduction::kMean: return "mean";
  }
  return "?";
}

std::string WindowText(const spec::TimeWindow& window) {
  if (window.whole_grid()) return "";
  return absl::StrFormat(" from %s to %s", window.from_s ? absl::StrFormat("%g s", *window.from_s) : "the start",
                         window.to_s ? absl::StrFormat("%g s", *window.to_s) : "the end");
}

}  // namespace mbopt::client
