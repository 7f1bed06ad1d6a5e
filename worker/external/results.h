// A driver's results: named values and named time series, read from the
// results file it wrote, in one of two formats (docs/external.md):
//  - JSON: {"values": {"name": number, ...}, "series": {"name": [numbers], ...},
//    "time": [numbers]}; every key optional, no other key allowed, none
//    twice in one object; when "time" is given every series has its length.
//  - Dakota: one "value name" per line (blank lines skipped), as the results
//    files of Dakota's fork interface without gradients.
// Errors are InvalidArgument naming the file and the line (and the column or
// field where there is one). Non-finite numbers are read, not refused: the
// runner reports them as non-finite values, a failure of the analysis.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "worker/external/driver.h"

namespace mbopt::external {

struct ExternalResults {
  std::map<std::string, double> values;
  std::map<std::string, std::vector<double>> series;
  std::vector<double> time_s;  // empty when the driver wrote none

  // The first non-finite number as "values.x" or "series.y[3]" or
  // "time[0]"; empty when every number is finite.
  std::string FirstNonFinite() const;
};

// `source` names the file in messages.
absl::StatusOr<ExternalResults> ParseJsonResults(const std::string& text, const std::string& source);
absl::StatusOr<ExternalResults> ParseDakotaResults(const std::string& text, const std::string& source);
absl::StatusOr<ExternalResults> ParseResults(ResultsFormat format, const std::string& text,
                                             const std::string& source);

}  // namespace mbopt::external
