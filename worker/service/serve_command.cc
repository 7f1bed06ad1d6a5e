#include "worker/service/serve_command.h"

#include <cerrno>
#include <cstdio>
#include <cstdlib>

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
  return "usage: mbopt-worker serve --server HOST:PORT [--slots N] [--name NAME]\n"
         "       mbopt-worker --server HOST:PORT [--slots N] [--name NAME]\n"
         "  --slots N            analyses run at once (default 1)\n"
         "  --name NAME          name shown by the server (default host:pid)\n"
         "  --verbose            one line on stderr per task\n"
         "  --die-after-tasks N  testing only: SIGKILL this process on receiving the\n"
         "                       N-th task, before reporting it\n";
}

int ServeMain(const std::vector<std::string>& args) {
  WorkerOptions options;
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
    if (name == "--server") {
      ok = need_value();
      options.server_address = value;
    } else if (name == "--slots") {
      ok = need_value() && ParseInt(value, 1, &options.slots);
    } else if (name == "--name") {
      ok = need_value();
      options.name = value;
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
  // Leaked on purpose: the signal thread may outlive this function.
  auto* stop = new StopSignal();
  StopOnTerminationSignals(stop);
  absl::Status status = RunWorker(options, *stop);
  if (!status.ok()) {
    std::fprintf(stderr, "mbopt-worker: %s\n", std::string(status.message()).c_str());
    return 2;
  }
  return 0;
}

}  // namespace mbopt::worker
