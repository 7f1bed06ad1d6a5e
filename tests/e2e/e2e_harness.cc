#include "tests/e2e/e2e_harness.h"

#include <stdlib.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "client/local_cluster.h"
#include "common/check.h"

namespace mbopt::e2e {

std::string MboptBinary() { return MBOPT_E2E_MBOPT; }
std::string ServerBinary() { return MBOPT_E2E_SERVER; }
std::string WorkerBinary() { return MBOPT_E2E_WORKER; }
std::string VehicleStudy() {
  return std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/vehicle/vehicle.study.textproto";
}

std::string ExternalStudy() {
  return std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/external/quarter_car.study.textproto";
}

std::string ExternalDrivers() {
  return std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/external/quarter_car.drivers.textproto";
}

std::string VehicleSensitivityStudy() {
  return std::string(MBOPT_E2E_SOURCE_DIR) + "/examples/vehicle/vehicle_sensitivity.study.textproto";
}

ScratchDir::ScratchDir() {
  std::string pattern = (std::filesystem::temp_directory_path() / "mbopt-e2e-XXXXXX").string();
  MBOPT_CHECK(mkdtemp(pattern.data()) != nullptr, "mkdtemp failed");
  path_ = pattern;
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::string ScratchDir::Write(const std::string& name, const std::string& text) const {
  const std::string p = File(name);
  std::ofstream(p) << text;
  return p;
}

absl::StatusOr<ServerProcess> StartServer(const std::string& db,
                                          const std::vector<std::string>& extra_args,
                                          const std::string& listen,
                                          const std::string& log_file) {
  std::vector<std::string> argv = {ServerBinary(), "--listen", listen, "--db", db};
  argv.insert(argv.end(), extra_args.begin(), extra_args.end());
  client::SpawnOptions options;
  options.capture_stdout = true;
  options.stderr_path = log_file;
  auto process = client::Subprocess::Start(argv, options);
  if (!process.ok()) return process.status();
  ServerProcess server;
  server.process = std::make_unique<client::Subprocess>(*std::move(process));
  auto line = server.process->ReadStdoutLine(kGuard);
  if (!line.ok()) return line.status();
  auto address = client::ParseListeningLine(*line);
  if (!address.ok()) return address.status();
  server.address = *address;
  server.port = std::stoi(server.address.substr(server.address.rfind(':') + 1));
  return server;
}

client::Subprocess StartWorker(const std::string& address,
                               const std::vector<std::string>& extra_args,
                               const std::string& log_file) {
  std::vector<std::string> argv = {WorkerBinary(), "serve", "--server", address};
  argv.insert(argv.end(), extra_args.begin(), extra_args.end());
  client::SpawnOptions options;
  options.silence_stdout = true;
  if (log_file.empty()) {
    options.silence_stderr = true;
  } else {
    options.stderr_path = log_file;
  }
  auto process = client::Subprocess::Start(argv, options);
  MBOPT_CHECK(process.ok(), "cannot start mbopt-worker");
  return *std::move(process);
}

client::Subprocess::Output Mbopt(const std::vector<std::string>& args,
                                 const std::vector<std::string>& extra_env) {
  std::vector<std::string> argv = {MboptBinary()};
  argv.insert(argv.end(), args.begin(), args.end());
  // Databases that `mbopt run` keeps go to this test program's own state
  // directory, removed at exit, never to the user's.
  static const ScratchDir state;
  std::vector<std::string> env = extra_env;
  if (std::none_of(env.begin(), env.end(), [](const std::string& e) { return e.rfind("XDG_STATE_HOME=", 0) == 0; })) {
    env.push_back("XDG_STATE_HOME=" + state.path());
  }
  auto out = client::RunCommand(argv, kGuard, env);
  if (!out.ok()) {
    client::Subprocess::Output failed;
    failed.exit_code = -1;
    failed.stderr_text = std::string(out.status().message());
    return failed;
  }
  return *out;
}

std::string Comparable(const std::string& results_json) {
  std::istringstream in(results_json);
  std::string line, out;
  while (std::getline(in, line)) {
    if (line.find("\"job_id\":") != std::string::npos || line.find("\"database\":") != std::string::npos ||
        line.find("\"wall_seconds\":") != std::string::npos) {
      continue;
    }
    out += line + "\n";
  }
  return out;
}

std::string JsonField(const std::string& json, const std::string& key) {
  const std::string needle = "\n  \"" + key + "\": ";
  auto pos = json.find(needle);
  if (pos == std::string::npos) return "";
  pos += needle.size();
  auto end = json.find('\n', pos);
  std::string value = json.substr(pos, end - pos);
  if (!value.empty() && value.back() == ',') value.pop_back();
  if (value.size() >= 2 && value.front() == '"') value = value.substr(1, value.size() - 2);
  return value;
}

std::vector<int> HistoryCycles(const std::string& json) {
  std::vector<int> cycles;
  const std::string needle = "\"cycle\": ";
  for (auto pos = json.find(needle); pos != std::string::npos; pos = json.find(needle, pos + 1)) {
    cycles.push_back(std::atoi(json.c_str() + pos + needle.size()));
  }
  return cycles;
}

std::string Trim(const std::string& s) {
  auto b = s.find_first_not_of(" \n\r\t");
  auto e = s.find_last_not_of(" \n\r\t");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

}  // namespace mbopt::e2e
