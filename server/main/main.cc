// mbopt-server: the optimizer server. Command line and behaviour are in
// docs/server.md.
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "server/main/flag_value.h"
#include "server/main/gc_command.h"
#include "server/service/listen_address.h"
#include "server/service/server.h"
#include "server/store/store.h"

namespace {

constexpr const char* kUsage =
    "usage: mbopt-server [--listen HOST:PORT [--insecure]] [--db PATH] [--port-file FILE]\n"
    "                    [--lease-ms N] [--heartbeat-ms N] [--max-message-mb N]\n"
    "                    [--durability full|normal] [--crash-after-cycles N]\n"
    "       mbopt-server gc --db PATH [--keep N] [--older-than-days D] [--export FILE]\n"
    "                    (prunes finished jobs; `mbopt-server gc --help`)\n"
    "  --listen ADDR          address to listen on (default 127.0.0.1:50051; port 0: any free port);\n"
    "                         only loopback addresses unless --insecure\n"
    "  --insecure             allow an address other machines can reach, without TLS\n"
    "                         or authentication (a warning at every start)\n"
    "  --db PATH              job database (default mbopt.db; created if missing)\n"
    "  --port-file FILE       write the port listened on to FILE once ready\n"
    "  --lease-ms N           lease of a task given to a worker (default 30000)\n"
    "  --heartbeat-ms N       heartbeat interval asked of workers (default 5000)\n"
    "  --durability full|normal  full (default): every commit synced to disk;\n"
    "                         normal: a machine crash may lose the last commits,\n"
    "                         which a resume analyses again (docs/store.md)\n"
    "  --max-message-mb N     largest message taken or sent, a result or a study\n"
    "                         (default 256, at most 2047)\n"
    "  --crash-after-cycles N testing: kill the server (SIGKILL) right after it\n"
    "                         commits its N-th cycle record\n";

struct Flags {
  mbopt::service::ServerOptions server;
  std::string port_file;
  std::int64_t crash_after_records = 0;
};

bool ParseInt(const std::string& flag, const std::string& text, std::int64_t min, std::int64_t* out) {
  if (!absl::SimpleAtoi(text, out) || *out < min) {
    std::cerr << "mbopt-server: " << flag << " needs an integer >= " << min << ", got '" << text << "'\n";
    return false;
  }
  return true;
}

// Returns false (after printing why) for a bad command line.
bool ParseFlags(int argc, char** argv, Flags* flags) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      std::exit(0);
    }
    if (arg == "--insecure") {
      flags->server.insecure = true;
      continue;
    }
    std::string name, value;
    if (!mbopt::server_main::FlagValue(argc, argv, &i, &name, &value)) {
      std::cerr << "mbopt-server: " << arg << " needs a value\n" << kUsage;
      return false;
    }
    std::int64_t number = 0;
    if (name == "--listen") {
      flags->server.listen_address = value;
    } else if (name == "--db") {
      flags->server.db_path = value;
    } else if (name == "--port-file") {
      flags->port_file = value;
    } else if (name == "--lease-ms") {
      if (!ParseInt(name, value, 1, &number)) return false;
      flags->server.lease_ms = number;
    } else if (name == "--heartbeat-ms") {
      if (!ParseInt(name, value, 1, &number)) return false;
      flags->server.heartbeat_ms = number;
    } else if (name == "--durability") {
      const std::optional<mbopt::store::Durability> durability = mbopt::store::ParseDurability(value);
      if (!durability) {
        std::cerr << "mbopt-server: --durability is full or normal, got '" << value << "'\n";
        return false;
      }
      flags->server.durability = *durability;
    } else if (name == "--max-message-mb") {
      if (!ParseInt(name, value, 1, &number)) return false;
      if (number > 2047) {
        std::cerr << "mbopt-server: --max-message-mb is at most 2047 (gRPC's limit is 2 GB), got " << number << "\n";
        return false;
      }
      flags->server.max_message_bytes = number << 20;
    } else if (name == "--crash-after-cycles") {
      if (!ParseInt(name, value, 1, &number)) return false;
      flags->crash_after_records = number;
    } else {
      std::cerr << "mbopt-server: unknown option '" << name << "'\n" << kUsage;
      return false;
    }
  }
  return true;
}

// Written to a temporary file and renamed, so a reader never sees half a port.
bool WritePortFile(const std::string& path, int port) {
  const std::string temp = absl::StrCat(path, ".tmp.", ::getpid());
  {
    std::ofstream out(temp, std::ios::trunc);
    out << port << "\n";
    out.flush();
    if (!out) {
      std::cerr << "mbopt-server: cannot write " << temp << "\n";
      return false;
    }
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    std::cerr << "mbopt-server: cannot rename " << temp << " to " << path << ": " << std::strerror(errno) << "\n";
    std::remove(temp.c_str());
    return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "gc") return mbopt::server_main::RunGcCommand(argc - 2, argv + 2);
  Flags flags;
  if (!ParseFlags(argc, argv, &flags)) return 2;
  if (flags.server.heartbeat_ms >= flags.server.lease_ms) {
    // Keep the default heartbeat sensible for short test leases.
    flags.server.heartbeat_ms = std::max<std::int64_t>(1, flags.server.lease_ms / 3);
  }
  if (flags.crash_after_records > 0) {
    const std::int64_t crash_at = flags.crash_after_records;
    flags.server.manager.after_record_commit = [crash_at](std::int64_t committed) {
      if (committed == crash_at) ::raise(SIGKILL);
    };
  }

  // Signals are taken synchronously by this thread; every other thread
  // (gRPC, reaper) inherits the blocked mask.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  absl::StatusOr<std::unique_ptr<mbopt::service::MboptServer>> server =
      mbopt::service::MboptServer::Start(flags.server);
  if (!server.ok()) {
    std::cerr << "mbopt-server: " << server.status().message() << "\n";
    return 1;
  }
  if (!flags.port_file.empty() && !WritePortFile(flags.port_file, (*server)->port())) {
    (*server)->Shutdown();
    return 1;
  }
  if (flags.server.insecure && !mbopt::service::IsLoopbackAddress(flags.server.listen_address)) {
    std::cerr << "mbopt-server: WARNING: listening on " << (*server)->address()
              << " without TLS or authentication (--insecure): anyone who can reach this port can submit, read "
                 "and cancel jobs and report results\n";
  }
  std::cout << "mbopt-server listening on " << (*server)->address() << std::endl;

  int signal_number = 0;
  while (sigwait(&stop_signals, &signal_number) != 0) {
  }
  std::cerr << "mbopt-server: " << (signal_number == SIGINT ? "SIGINT" : "SIGTERM")
            << ": stopping; running jobs resume on the next start\n";
  (*server)->Shutdown();
  return 0;
}
