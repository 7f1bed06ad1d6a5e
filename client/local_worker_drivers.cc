#include "client/local_worker_drivers.h"

#include <chrono>
#include <filesystem>
#include <system_error>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "client/subprocess.h"

namespace mbopt::client {

absl::StatusOr<std::vector<std::string>> LocalWorkerDriverArgs(const ParsedArgs& parsed,
                                                               const std::string& worker_binary) {
  const std::string drivers = parsed.Value("--drivers");
  if (drivers.empty()) {
    if (parsed.Has("--keep-runs")) return absl::InvalidArgumentError("--keep-runs needs --drivers FILE");
    return std::vector<std::string>{};
  }
  std::error_code ec;
  const std::string absolute = std::filesystem::absolute(drivers, ec).string();
  if (ec) return absl::InvalidArgumentError(absl::StrCat("--drivers ", drivers, ": ", ec.message()));
  absl::StatusOr<Subprocess::Output> checked =
      RunCommand({worker_binary, "drivers", absolute}, std::chrono::seconds(60));
  if (!checked.ok()) return checked.status();
  if (checked->exit_code != 0) {
    return absl::InvalidArgumentError(absl::StrCat("--drivers ", drivers, ":\n", checked->stderr_text));
  }
  std::vector<std::string> args = {"--drivers", absolute};
  if (parsed.Has("--keep-runs")) args.push_back("--keep-runs");
  return args;
}

std::string DriverArgsText(const std::vector<std::string>& worker_args) {
  return worker_args.empty() ? "" : " " + absl::StrJoin(worker_args, " ");
}

}  // namespace mbopt::client
