#include "worker/main/drivers_command.h"

#include <ostream>

#include "absl/strings/str_join.h"
#include "worker/external/drivers_file.h"
#include "worker/main/eval_command.h"

namespace mbopt::worker {

const char* DriversUsage() {
  return "usage: mbopt-worker drivers FILE\n"
         "  Checks a drivers file (docs/external.md) and lists its drivers with\n"
         "  their parameters; exit status 0 good, 2 a problem (each one named).\n";
}

int RunDrivers(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  if (args.size() == 1 && (args[0] == "--help" || args[0] == "-h")) {
    out << DriversUsage();
    return kExitOk;
  }
  if (args.size() != 1 || args[0].empty() || args[0][0] == '-') {
    err << DriversUsage();
    return kExitBadInput;
  }
  absl::StatusOr<std::vector<external::DriverDeclaration>> drivers = external::LoadDriversFile(args[0]);
  if (!drivers.ok()) {
    err << drivers.status().message() << "\n";
    return kExitBadInput;
  }
  for (const external::DriverDeclaration& driver : *drivers) {
    out << driver.name << ": " << absl::StrJoin(driver.command, " ") << "\n  parameters: "
        << (driver.parameters.empty() ? "none" : absl::StrJoin(driver.parameters, ", ")) << "\n";
  }
  return kExitOk;
}

}  // namespace mbopt::worker
