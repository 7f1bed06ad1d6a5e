// The external-analysis options a worker program takes (`--drivers FILE`,
// `--work-dir DIR`, `--keep-runs`), shared by `mbopt-worker serve` and
// `mbopt-worker eval`, turned into the settings every external analysis of
// the process uses.
#pragma once

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "worker/external/scene_analyzer.h"

namespace mbopt::external {

struct ExternalOptions {
  std::string drivers_file;    // empty: no drivers (external scenes fail)
  std::string work_directory;  // empty: <temp dir>/mbopt-runs-<pid>
  bool keep_runs = false;
};

// Whether `name` is one of the options above, and taking a value.
bool IsExternalOption(const std::string& name, bool* takes_value);
// Sets option `name` (one IsExternalOption accepts); false when the value
// is not acceptable.
bool SetExternalOption(const std::string& name, const std::string& value, ExternalOptions* options);

// The drivers file read and checked (every problem named with file, line and
// field); null settings when no drivers file is given.
absl::StatusOr<std::unique_ptr<ExternalWorkerSettings>> LoadExternalSettings(const ExternalOptions& options);

// Removes the default work directory (<temp dir>/mbopt-runs-<pid>) when the
// process leaves it empty; a directory given with --work-dir is the
// user's and stays.
void RemoveDefaultWorkDirectoryIfEmpty(const ExternalOptions& options, const ExternalWorkerSettings* settings);

// The options' lines of a usage text.
const char* ExternalOptionsUsage();

}  // namespace mbopt::external
