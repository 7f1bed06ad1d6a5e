// A driver's results: named values and named time series, read from the
// results file it wrote, in one of two formats (docs/external.md):
//  - JSON: {"values": {"name": number, ...}, "series": {"name": [numbers], ...},
//    "time": [numbers], "gradients": {"values": {"name": {"parameter":
//    number, ...}}, "series": {"name": {"parameter": [numbers], ...}}}};
//    every key optional, no other key allowed, none twice in one object;
//    when "time" is given every series has its length, and a series'
//    gradient always has the series' length.
//  - Dakota: one "value name" per line (blank lines skipped), as the results
//    files of Dakota's fork interface, then optionally one gradient line
//    "[ g1 g2 ... ]" per value in the same order, its numbers the
//    derivatives with respect to the driver's parameters in their declared
//    order (Hessians, "[[ ... ]]", are refused).
// Gradients are derivatives with respect to the driver's own parameters
// (the values the runner wrote into the input), in SI.
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
  // d value / d parameter: [value name][driver parameter name].
  std::map<std::string, std::map<std::string, double>> value_gradients;
  // d series / d parameter, one number per number of the series:
  // [series name][driver parameter name].
  std::map<std::string, std::map<std::string, std::vector<double>>> series_gradients;

  // The first non-finite number as "values.x" or "series.y[3]" or
  // "time[0]" or "gradients.values.x.p"; empty when every number is finite.
  std::string FirstNonFinite() const;
};

// `source` names the file in messages. `parameters` are the driver's
// declared parameters: the names of a Dakota gradient line's numbers, in
// order (a gradient line of another length is an error).
absl::StatusOr<ExternalResults> ParseJsonResults(const std::string& text, const std::string& source);
absl::StatusOr<ExternalResults> ParseDakotaResults(const std::string& text, const std::string& source,
                                                   const std::vector<std::string>& parameters = {});
absl::StatusOr<ExternalResults> ParseResults(ResultsFormat format, const std::string& text,
                                             const std::string& source,
                                             const std::vector<std::string>& parameters = {});

}  // namespace mbopt::external
