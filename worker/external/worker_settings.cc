#include "worker/external/worker_settings.h"

#include <unistd.h>

#include <filesystem>

#include "absl/strings/str_cat.h"
#include "worker/external/drivers_file.h"

namespace mbopt::external {

bool IsExternalOption(const std::string& name, bool* takes_value) {
  *takes_value = name == "--drivers" || name == "--work-dir";
  return *takes_value || name == "--keep-runs";
}

bool SetExternalOption(const std::string& name, const std::string& value, ExternalOptions* options) {
  if (name == "--drivers") {
    options->drivers_file = value;
    return !value.empty();
  }
  if (name == "--work-dir") {
    options->work_directory = value;
    return !value.empty();
  }
  if (name == "--keep-runs") {
    options->keep_runs = true;
    return true;
  }
  return false;
}

absl::StatusOr<std::unique_ptr<ExternalWorkerSettings>> LoadExternalSettings(const ExternalOptions& options) {
  if (options.drivers_file.empty()) {
    if (!options.work_directory.empty() || options.keep_runs) {
      return absl::InvalidArgumentError("--work-dir and --keep-runs need --drivers FILE");
    }
    return std::unique_ptr<ExternalWorkerSettings>();
  }
  absl::StatusOr<std::vector<DriverDeclaration>> drivers = LoadDriversFile(options.drivers_file);
  if (!drivers.ok()) return drivers.status();
  auto settings = std::make_unique<ExternalWorkerSettings>();
  settings->drivers = *std::move(drivers);
  settings->keep_run_folders = options.keep_runs;
  std::error_code ec;
  if (options.work_directory.empty()) {
    // One directory per process: two workers on one machine never meet.
    settings->work_directory =
        std::filesystem::temp_directory_path(ec) / absl::StrCat("mbopt-runs-", static_cast<long>(getpid()));
    if (ec) return absl::FailedPreconditionError(absl::StrCat("no temporary directory: ", ec.message()));
  } else {
    settings->work_directory = std::filesystem::absolute(options.work_directory, ec);
    if (ec) {
      return absl::InvalidArgumentError(absl::StrCat("--work-dir ", options.work_directory, ": ", ec.message()));
    }
  }
  return settings;
}

void RemoveDefaultWorkDirectoryIfEmpty(const ExternalOptions& options, const ExternalWorkerSettings* settings) {
  if (settings == nullptr || !options.work_directory.empty()) return;
  std::error_code ec;
  if (std::filesystem::is_empty(settings->work_directory, ec) && !ec) {
    std::filesystem::remove(settings->work_directory, ec);
  }
}

const char* ExternalOptionsUsage() {
  return "  --drivers FILE       the analysis drivers this worker offers (a\n"
         "                       .drivers.textproto, docs/external.md): the external\n"
         "                       simulation codes `external` scenes may name\n"
         "  --work-dir DIR       where per-analysis folders go (default\n"
         "                       <temp dir>/mbopt-runs-<pid>)\n"
         "  --keep-runs          keep every analysis folder instead of removing it\n"
         "                       once its result is read\n";
}

}  // namespace mbopt::external
