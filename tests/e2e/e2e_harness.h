// Real processes for the end-to-end tests: an mbopt-server on 127.0.0.1 with
// an OS-chosen port (readiness read from its stdout line), mbopt-worker
// processes, and the mbopt CLI run to completion with its output captured.
// Binary paths come from the build (compile definitions). Deadlines here are
// failure guards only; nothing waits by sleeping.
#pragma once

#include <chrono>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "client/subprocess.h"

namespace mbopt::e2e {

inline constexpr auto kGuard = std::chrono::seconds(180);

std::string MboptBinary();
std::string ServerBinary();
std::string WorkerBinary();
// The vehicle example (examples/vehicle/vehicle.study.textproto).
std::string VehicleStudy();
// The external-simulator example (examples/external): its study, and the
// drivers file its workers need (--drivers).
std::string ExternalStudy();
std::string ExternalDrivers();

// The same problem with simulator sensitivities
// (examples/vehicle/vehicle_sensitivity.study.textproto).
std::string VehicleSensitivityStudy();

// A fresh directory under the system's temporary directory, removed at
// destruction.
class ScratchDir {
 public:
  ScratchDir();
  ~ScratchDir();
  const std::string& path() const { return path_; }
  std::string File(const std::string& name) const { return path_ + "/" + name; }
  std::string Write(const std::string& name, const std::string& text) const;

 private:
  std::string path_;
};

struct ServerProcess {
  std::unique_ptr<client::Subprocess> process;
  std::string address;  // host:port
  int port = 0;
};

// Starts mbopt-server on `listen` (default: port 0) with `db` and extra
// arguments, and waits for its readiness line.
absl::StatusOr<ServerProcess> StartServer(const std::string& db,
                                          const std::vector<std::string>& extra_args = {},
                                          const std::string& listen = "127.0.0.1:0",
                                          const std::string& log_file = "");

client::Subprocess StartWorker(const std::string& address,
                               const std::vector<std::string>& extra_args = {},
                               const std::string& log_file = "");

// Runs `mbopt args...` to completion.
client::Subprocess::Output Mbopt(const std::vector<std::string>& args,
                                 const std::vector<std::string>& extra_env = {});

// `results --json` without the fields that legitimately differ between two
// runs of one study (job id, database path, wall time): what "the same
// result" means.
std::string Comparable(const std::string& results_json);
// The value of a top-level "key": value line of the CLI's JSON ("" if absent).
std::string JsonField(const std::string& json, const std::string& key);
// The cycle numbers of the history entries, in order.
std::vector<int> HistoryCycles(const std::string& json);

std::string Trim(const std::string& s);

}  // namespace mbopt::e2e
