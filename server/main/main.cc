// mbopt-server: the optimizer server. Command line and behaviour are in
// docs/server.md.
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
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
#include "common/read_file.h"
#include "common/version/version.h"
#include "server/auth/certificates.h"
#include "server/main/flag_value.h"
#include "server/main/gc_command.h"
#include "server/main/init_tls_command.h"
#include "server/main/listener_failure.h"
#include "server/main/renew_cert_command.h"
#include "server/service/listen_address.h"
#include "server/service/server.h"
#include "server/store/store.h"

namespace {

constexpr const char* kUsage =
    "usage: mbopt-server [--listen HOST:PORT] [--tls-dir DIR | --tls-cert F --tls-key F --tokens F]\n"
    "                    [--worker-ca F] [--insecure] [--db PATH] [--inspect] [--port-file FILE]\n"
    "                    [--lease-ms N] [--heartbeat-ms N] [--max-message-mb N] [--max-result-mb N]\n"
    "                    [--durability full|cycles|normal]\n"
    "                    [--max-running-jobs N] [--max-running-jobs-per-user N] [--max-queued-jobs-per-user N]\n"
    "                    [--max-calls-per-second-per-user N] [--verify-fraction F]\n"
    "                    [--max-call-threads N] [--max-streams-per-connection N] [--max-held-calls-per-peer N]\n"
    "                    [--crash-after-cycles N] [--crash-in-commit N]\n"
    "       mbopt-server init-tls DIR [--host NAME]... [--user NAME]... [--worker NAME]...\n"
    "                    (a CA, certificates and tokens; `mbopt-server init-tls --help`)\n"
    "       mbopt-server add-token --tokens F --role worker|user|admin --name N --out F\n"
    "       mbopt-server add-token worker|user|admin NAME --tokens F --out F\n"
    "       mbopt-server renew-cert DIR [--host NAME]... [--days N]\n"
    "       mbopt-server gc --db PATH [--keep N] [--older-than-days D] [--export FILE]\n"
    "                    (prunes finished jobs; `mbopt-server gc --help`)\n"
    "       mbopt-server --version   (the release, the commit, the schema versions)\n"
    "  --listen ADDR          address to listen on (default 127.0.0.1:50051; port 0: any free port);\n"
    "                         an address other machines can reach needs TLS and tokens\n"
    "  --tls-dir DIR          what `init-tls DIR` made: DIR/server.pem, DIR/server.key\n"
    "                         and DIR/tokens (each overridden by its own option)\n"
    "  --tls-cert F, --tls-key F  the server's certificate and key (PEM): TLS\n"
    "  --tokens F             the token table; every call then needs a token\n"
    "  --worker-ca F          workers must also present a client certificate\n"
    "                         signed by this CA (mutual TLS)\n"
    "  --insecure             allow an address other machines can reach without TLS\n"
    "                         and tokens (a warning at every start)\n"
    "  SIGHUP reads the token table again (to add or revoke tokens).\n"
    "  --db PATH              job database (default mbopt.db; created if missing)\n"
    "  --inspect              only show the database's jobs: resume, admit, take\n"
    "                         and cancel none; a job it calls running is shown\n"
    "                         interrupted (`mbopt status --db` starts one)\n"
    "  --port-file FILE       write the port listened on to FILE once ready\n"
    "  --lease-ms N           lease of a task given to a worker (default 30000)\n"
    "  --heartbeat-ms N       heartbeat interval asked of workers (default 5000)\n"
    "  --durability full|cycles|normal  what a machine crash (power loss) may take\n"
    "                         (a crash of the server alone loses nothing): full:\n"
    "                         nothing, every commit synced; cycles (default): the\n"
    "                         results of the cycle in progress; normal: the last\n"
    "                         commits. A resume analyses again what was lost and\n"
    "                         ends with the same result (docs/store.md)\n"
    "  --max-message-mb N     largest message taken or sent, a result or a study,\n"
    "                         in MiB (default 256, from 0.0625 to 2047)\n"
    "  --max-result-mb N      largest result taken, in pieces when over the\n"
    "                         message limit, in MiB (default 1024); the server\n"
    "                         holds one such result whole while it arrives\n"
    "  --max-running-jobs N   jobs that run at once (default 64); the others wait,\n"
    "                         QUEUED, and start in submission order (0: no limit)\n"
    "  --max-running-jobs-per-user N  the same per user (default 16)\n"
    "  --max-queued-jobs-per-user N   waiting jobs a user may have; more are refused\n"
    "                         at submit (default 1000)\n"
    "  --max-calls-per-second-per-user N  job calls a user token may make per\n"
    "                         second, in bursts of twice that (default 100; 0: no\n"
    "                         limit; admins and workers are not limited)\n"
    "  --max-call-threads N   threads the server runs calls on (default 1024, at\n"
    "                         least 8): a call that needs one more is refused\n"
    "                         (RESOURCE_EXHAUSTED); a worker holds about 2, a\n"
    "                         watcher 1\n"
    "  --max-streams-per-connection N  calls one connection may have open at once\n"
    "                         (default 100); more wait in the client\n"
    "  --max-held-calls-per-peer N  calls one address may hold open (watches, attach\n"
    "                         streams, long polls; default 512, 0: no limit); a\n"
    "                         worker holds about 2\n"
    "  --verify-fraction F    spot checks: the share of analyses (0 to 1) computed\n"
    "                         again by another worker and compared bit for bit; a\n"
    "                         worker two others contradict is quarantined (default 0)\n"
    "  --crash-after-cycles N testing: kill the server (SIGKILL) right after it\n"
    "                         commits its N-th cycle record\n"
    "  --crash-in-commit N    testing: kill the server (SIGKILL) in the middle of\n"
    "                         its N-th transaction of results, before COMMIT\n";

// The exit status when gRPC's listener stopped accepting (listener_failure.h):
// not 0, so that a service manager restarts the server (EX_TEMPFAIL).
constexpr int kExitListenerFailed = 75;

// Every connection takes a descriptor; a service's soft limit (1024 under
// systemd) is filled by as many idle connections from anyone who can reach
// the port. The hard limit is what the administrator allows: use it all.
void RaiseOpenFilesLimit() {
  rlimit limit{};
  if (::getrlimit(RLIMIT_NOFILE, &limit) != 0) return;
  const rlim_t before = limit.rlim_cur;
  if (limit.rlim_cur != RLIM_INFINITY && limit.rlim_cur < limit.rlim_max) {
    limit.rlim_cur = limit.rlim_max;
    if (::setrlimit(RLIMIT_NOFILE, &limit) != 0) {
      std::cerr << "mbopt-server: cannot raise the open-files limit from " << before << " to " << limit.rlim_max
                << ": " << std::strerror(errno) << "\n";
      return;
    }
    std::cerr << "mbopt-server: open-files limit raised from " << before << " to " << limit.rlim_cur << "\n";
  }
}

// A certificate this close to expiring is warned about at every start.
constexpr std::int64_t kCertificateWarningSeconds = std::int64_t{30} * 86400;

struct Flags {
  mbopt::service::ServerOptions server;
  std::string tls_dir;
  std::string port_file;
  std::int64_t crash_after_records = 0;
  std::int64_t crash_in_commit = 0;
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
    if (arg == "--inspect") {
      flags->server.manager.inspect_only = true;
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
    } else if (name == "--tls-dir") {
      flags->tls_dir = value;
    } else if (name == "--tls-cert") {
      flags->server.tls_cert_file = value;
    } else if (name == "--tls-key") {
      flags->server.tls_key_file = value;
    } else if (name == "--tokens") {
      flags->server.tokens_file = value;
    } else if (name == "--worker-ca") {
      flags->server.worker_ca_file = value;
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
        std::cerr << "mbopt-server: --durability is full, cycles or normal, got '" << value << "'\n";
        return false;
      }
      flags->server.durability = *durability;
    } else if (name == "--max-message-mb") {
      // Decimals allowed: small limits are how a test (or a cautious site)
      // sees results refused without simulating millions of instants.
      double mb = 0;
      if (!absl::SimpleAtod(value, &mb) || !(mb >= 0.0625) || mb > 2047) {
        std::cerr << "mbopt-server: --max-message-mb is a number from 0.0625 to 2047 (gRPC's limit is 2 GB), got '"
                  << value << "'\n";
        return false;
      }
      flags->server.max_message_bytes = std::llround(mb * (1 << 20));
    } else if (name == "--max-result-mb") {
      double mb = 0;
      if (!absl::SimpleAtod(value, &mb) || !(mb >= 0.0625) || mb > 65536) {
        std::cerr << "mbopt-server: --max-result-mb is a number from 0.0625 to 65536, got '" << value << "'\n";
        return false;
      }
      flags->server.max_result_bytes = std::llround(mb * (1 << 20));
    } else if (name == "--max-running-jobs") {
      if (!ParseInt(name, value, 0, &number)) return false;
      flags->server.manager.admission.max_running_jobs = static_cast<int>(std::min<std::int64_t>(number, 1 << 30));
    } else if (name == "--max-running-jobs-per-user") {
      if (!ParseInt(name, value, 0, &number)) return false;
      flags->server.manager.admission.max_running_jobs_per_user =
          static_cast<int>(std::min<std::int64_t>(number, 1 << 30));
    } else if (name == "--max-queued-jobs-per-user") {
      if (!ParseInt(name, value, 0, &number)) return false;
      flags->server.manager.admission.max_queued_jobs_per_user =
          static_cast<int>(std::min<std::int64_t>(number, 1 << 30));
    } else if (name == "--max-calls-per-second-per-user") {
      double rate = 0;
      if (!absl::SimpleAtod(value, &rate) || !(rate >= 0) || rate > 1e6) {
        std::cerr << "mbopt-server: --max-calls-per-second-per-user is a number from 0 to 1e6, got '" << value
                  << "'\n";
        return false;
      }
      flags->server.max_calls_per_second_per_user = rate;
    } else if (name == "--max-call-threads") {
      // A few threads are gRPC's own pollers: below 8 calls would get almost none.
      if (!ParseInt(name, value, 8, &number)) return false;
      flags->server.max_call_threads = static_cast<int>(std::min<std::int64_t>(number, 1 << 20));
    } else if (name == "--max-streams-per-connection") {
      if (!ParseInt(name, value, 1, &number)) return false;
      flags->server.max_streams_per_connection = static_cast<int>(std::min<std::int64_t>(number, 1 << 20));
    } else if (name == "--max-held-calls-per-peer") {
      if (!ParseInt(name, value, 0, &number)) return false;
      flags->server.max_held_calls_per_peer = static_cast<int>(std::min<std::int64_t>(number, 1 << 20));
    } else if (name == "--verify-fraction") {
      double fraction = 0;
      if (!absl::SimpleAtod(value, &fraction) || !(fraction >= 0) || fraction > 1) {
        std::cerr << "mbopt-server: --verify-fraction is a number from 0 to 1 (the share of analyses checked), got '"
                  << value << "'\n";
        return false;
      }
      flags->server.manager.verify_fraction = fraction;
    } else if (name == "--crash-after-cycles") {
      if (!ParseInt(name, value, 1, &number)) return false;
      flags->crash_after_records = number;
    } else if (name == "--crash-in-commit") {
      if (!ParseInt(name, value, 1, &number)) return false;
      flags->crash_in_commit = number;
    } else {
      std::cerr << "mbopt-server: unknown option '" << name << "'\n" << kUsage;
      return false;
    }
  }
  if (!flags->tls_dir.empty()) {
    auto fill = [&](std::string* field, const char* file) {
      if (field->empty()) *field = flags->tls_dir + "/" + file;
    };
    fill(&flags->server.tls_cert_file, "server.pem");
    fill(&flags->server.tls_key_file, "server.key");
    fill(&flags->server.tokens_file, "tokens");
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
  if (argc >= 2 && (std::string(argv[1]) == "--version" || std::string(argv[1]) == "version")) {
    std::cout << mbopt::version::VersionText(
        "mbopt-server", {{"job database schema", std::to_string(mbopt::store::kSchemaVersion)}});
    return 0;
  }
  if (argc >= 2 && std::string(argv[1]) == "gc") return mbopt::server_main::RunGcCommand(argc - 2, argv + 2);
  if (argc >= 2 && std::string(argv[1]) == "init-tls") {
    return mbopt::server_main::RunInitTlsCommand(argc - 2, argv + 2);
  }
  if (argc >= 2 && std::string(argv[1]) == "renew-cert") {
    return mbopt::server_main::RunRenewCertCommand(argc - 2, argv + 2);
  }
  if (argc >= 2 && std::string(argv[1]) == "add-token") {
    return mbopt::server_main::RunAddTokenCommand(argc - 2, argv + 2);
  }
  Flags flags;
  // Admission defaults (docs/server.md, "Admission"): a server shared by
  // many users runs a bounded number of jobs, and no user crowds out others.
  flags.server.manager.admission.max_running_jobs = 64;
  flags.server.manager.admission.max_running_jobs_per_user = 16;
  flags.server.manager.admission.max_queued_jobs_per_user = 1000;
  flags.server.max_calls_per_second_per_user = 100;
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

  if (flags.crash_in_commit > 0) {
    const std::int64_t crash_at = flags.crash_in_commit;
    flags.server.before_result_commit = [crash_at](std::int64_t transaction) {
      if (transaction == crash_at) ::raise(SIGKILL);
    };
  }

  RaiseOpenFilesLimit();
  mbopt::server_main::WatchForListenerFailure();

  // Signals are taken synchronously by this thread; every other thread
  // (gRPC, reaper) inherits the blocked mask.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGTERM);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGHUP);
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
  const bool tls = !flags.server.tls_cert_file.empty();
  const bool tokens = !flags.server.tokens_file.empty();
  if (flags.server.insecure && !mbopt::service::IsLoopbackAddress(flags.server.listen_address) && !(tls && tokens)) {
    std::cerr << "mbopt-server: WARNING: listening on " << (*server)->address() << " without "
              << (!tls && !tokens ? "TLS or tokens" : !tls ? "TLS" : "tokens")
              << " (--insecure): anyone who can reach this port can submit, read and cancel jobs and report "
                 "results\n";
  }
  if (tls || tokens) {
    std::cerr << "mbopt-server: " << (tls ? "TLS" : "no TLS") << ", "
              << (tokens ? "every call needs a token" : "no tokens")
              << (flags.server.worker_ca_file.empty() ? "" : ", workers need a certificate") << "\n";
  }
  if (tls) {
    // Started, so readable and not expired; say so well before it expires.
    absl::StatusOr<std::string> pem = mbopt::ReadWholeFile(flags.server.tls_cert_file);
    absl::StatusOr<mbopt::auth::CertificateInfo> info =
        pem.ok() ? mbopt::auth::InspectCertificate(*pem, flags.server.tls_cert_file) : pem.status();
    if (info.ok() && info->seconds_left < kCertificateWarningSeconds) {
      std::cerr << "mbopt-server: WARNING: the server certificate " << flags.server.tls_cert_file << " expires on "
                << info->not_after << "; `mbopt-server renew-cert DIR` makes a new one from the same CA\n";
    }
  }
  // The ready line scripts and `mbopt run` read: keep its form.
  std::cout << "mbopt-server listening on " << (*server)->address() << std::endl;

  int signal_number = 0;
  for (;;) {
    siginfo_t sender{};
    signal_number = sigwaitinfo(&stop_signals, &sender);
    if (signal_number < 0) continue;
    if (signal_number != SIGHUP) break;
    // Who asked, for the audit trail: a reload changes who may call.
    const std::string from = absl::StrCat("from pid ", sender.si_pid, " uid ", sender.si_uid);
    absl::StatusOr<std::size_t> reloaded = (*server)->ReloadTokens();
    if (reloaded.ok() && *reloaded == 0) {
      std::cerr << "mbopt-server: audit: SIGHUP " << from << ": WARNING: the token table "
                << flags.server.tokens_file
                << " is missing or lists no token: EVERY TOKEN IS REVOKED, no call is accepted until the table "
                   "lists tokens again (and SIGHUP)\n";
    } else if (reloaded.ok()) {
      std::cerr << "mbopt-server: audit: SIGHUP " << from << ": token table " << flags.server.tokens_file
                << " read again, " << *reloaded << " tokens\n";
    } else {
      std::cerr << "mbopt-server: audit: SIGHUP " << from << ": " << reloaded.status().message()
                << "; the table in use stays\n";
    }
  }
  const std::string listener_failure = mbopt::server_main::ListenerFailure();
  if (!listener_failure.empty()) {
    std::cerr << "mbopt-server: gRPC stopped accepting connections (" << listener_failure
              << "; it does not try again): stopping with status " << kExitListenerFailed
              << " so that the service manager starts the server again; running jobs resume then\n";
  } else {
    std::cerr << "mbopt-server: " << (signal_number == SIGINT ? "SIGINT" : "SIGTERM")
              << ": stopping; running jobs resume on the next start\n";
  }
  (*server)->Shutdown();
  return listener_failure.empty() ? 0 : kExitListenerFailed;
}
