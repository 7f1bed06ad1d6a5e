#include "worker/service/serve_command.h"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "worker/external/worker_settings.h"
#include "worker/service/stop_signal.h"
#include "worker/service/worker_service.h"

namespace mbopt::worker {
namespace {

bool ParseInt(const std::string& text, int min, int* out) {
  char* end = nullptr;
  errno = 0;
  long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno != 0 || v < min || v > 1000000) return false;
  *out = static_cast<int>(v);
  return true;
}

}  // namespace

const char* ServeUsage() {
  static const std::string usage = std::string(
         "usage: mbopt-worker serve --server HOST:PORT [--slots N] [--name NAME]\n"
         "                          [--tls-ca FILE [--tls-cert FILE --tls-key FILE]] [--token-file FILE]\n"
         "                          [--drivers FILE [--work-dir DIR] [--keep-runs]]\n"
         "       mbopt-worker --server HOST:PORT ... (the same)\n"
         "  --slots N            analyses run at once (default 1)\n"
         "  --name NAME          name shown by the server (default host:pid)\n"
         "  --batch N            take up to N tasks at a time and report their results\n"
         "                       together (default and most 64; never fewer than\n"
         "                       --slots); the server gives no worker more than its\n"
         "                       share of the work outstanding. 1: one task per slot\n"
         "  --tls-ca FILE        connect over TLS, trusting the server's certificate\n"
         "                       if this CA signed it (env MBOPT_TLS_CA)\n"
         "  --tls-cert FILE, --tls-key FILE  this worker's client certificate and key,\n"
         "                       for a server with --worker-ca (env MBOPT_TLS_CERT, MBOPT_TLS_KEY)\n"
         "  --tls-server-name N  the name the server's certificate must carry, when\n"
         "                       --server is another (a tunnel; env MBOPT_TLS_SERVER_NAME)\n"
         "  --token-file FILE    the worker token (env MBOPT_TOKEN_FILE, or MBOPT_TOKEN\n"
         "                       holding the token); never on the command line\n"
         "  Exit status: 0 stopped by a signal, 2 bad options, 3 the server refused the\n"
         "  token or the first connection failed for a reason of this configuration.\n"
         "  --verbose            one line on stderr per task (else one per batch)\n") +
      external::ExternalOptionsUsage() +
         "  --task-delay-ms N    testing only: hold each result N ms before reporting it\n"
         "  --die-after-tasks N  testing only: SIGKILL this process on receiving the\n"
         "                       N-th task, before reporting it\n";
  return usage.c_str();
}

int ServeMain(const std::vector<std::string>& args) {
  WorkerOptions options;
  external::ExternalOptions external_options;
  secure_channel::ClientSecurityFlags security_flags;
  for (size_t i = 0; i < args.size(); ++i) {
    std::string name = args[i], value;
    bool inline_value = false;
    if (auto eq = name.find('='); eq != std::string::npos && name.rfind("--", 0) == 0) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      inline_value = true;
    }
    auto need_value = [&]() -> bool {
      if (inline_value) return true;
      if (i + 1 >= args.size()) return false;
      value = args[++i];
      return true;
    };
    bool ok = true;
    bool external_takes_value = false;
    if (external::IsExternalOption(name, &external_takes_value)) {
      ok = (!external_takes_value || need_value()) && external::SetExternalOption(name, value, &external_options);
    } else if (name == "--server") {
      ok = need_value();
      options.server_address = value;
    } else if (name == "--slots") {
      ok = need_value() && ParseInt(value, 1, &options.slots);
    } else if (name == "--name") {
      ok = need_value();
      options.name = value;
    } else if (secure_channel::IsSecurityOption(name)) {
      ok = need_value() && secure_channel::SetSecurityFlag(name, value, &security_flags);
    } else if (name == "--batch") {
      ok = need_value() && ParseInt(value, 1, &options.batch) && options.batch <= kMaxBatch;
    } else if (name == "--task-delay-ms") {
      ok = need_value() && ParseInt(value, 0, &options.task_delay_ms);
    } else if (name == "--die-after-tasks") {
      ok = need_value() && ParseInt(value, 0, &options.die_after_tasks);
    } else if (name == "--verbose" && !inline_value) {
      options.verbose = true;
    } else if (name == "--help" || name == "-h") {
      std::fputs(ServeUsage(), stdout);
      return 0;
    } else {
      std::fprintf(stderr, "mbopt-worker: unknown argument '%s'\n%s", args[i].c_str(),
                   ServeUsage());
      return 2;
    }
    if (!ok) {
      std::fprintf(stderr, "mbopt-worker: bad or missing value for %s\n%s", name.c_str(),
                   ServeUsage());
      return 2;
    }
  }
  if (options.server_address.empty()) {
    std::fprintf(stderr, "mbopt-worker: --server HOST:PORT is required\n%s", ServeUsage());
    return 2;
  }
  // Read before connecting: a drivers file with a problem stops the worker
  // here, with every problem named, not at its first analysis.
  absl::StatusOr<std::unique_ptr<external::ExternalWorkerSettings>> external_settings =
      external::LoadExternalSettings(external_options);
  if (!external_settings.ok()) {
    std::fprintf(stderr, "mbopt-worker: %s\n", std::string(external_settings.status().message()).c_str());
    return 2;
  }
  // Never freed, like the stop signals below: worker threads may use them
  // until the process exits.
  options.external = external_settings->release();
  secure_channel::QuietGrpcLogUnlessAsked();
  absl::StatusOr<secure_channel::ClientSecurity> security = secure_channel::LoadClientSecurity(security_flags);
  if (!security.ok()) {
    std::fprintf(stderr, "mbopt-worker: %s\n", std::string(security.status().message()).c_str());
    return 2;
  }
  options.security = *std::move(security);
  // Never freed: the signal thread may outlive this function (and static
  // destruction at exit). Held where leak checkers see it reachable, as the
  // process's other lifetime objects are.
  static auto* const stop_signals = new std::vector<std::unique_ptr<StopSignal>>();
  StopSignal* stop = stop_signals->emplace_back(std::make_unique<StopSignal>()).get();
  StopOnTerminationSignals(stop);
  absl::Status status = RunWorker(options, *stop);
  external::RemoveDefaultWorkDirectoryIfEmpty(external_options, options.external);
  if (!status.ok()) {
    std::fprintf(stderr, "mbopt-worker: %s\n", std::string(status.message()).c_str());
    return absl::IsPermissionDenied(status) ? 3 : 2;
  }
  return 0;
}

}  // namespace mbopt::worker
