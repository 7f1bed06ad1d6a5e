#include "server/main/init_tls_command.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstring>
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "server/auth/certificates.h"
#include "server/auth/principal.h"
#include "server/auth/token.h"
#include "server/auth/token_table.h"
#include "server/main/flag_value.h"
#include "server/main/secret_file.h"

namespace mbopt::server_main {
namespace {

constexpr const char* kInitTlsUsage =
    "usage: mbopt-server init-tls DIR [--host NAME]... [--user NAME]... [--worker NAME]... [--days N]\n"
    "  Makes DIR (mode 0700) with what a server reachable from other machines\n"
    "  needs, then prints the commands that use it:\n"
    "    ca.pem, ca.key          the installation's certificate authority\n"
    "    server.pem, server.key  the server's certificate for the --host names\n"
    "    worker.pem, worker.key  a client certificate for workers (--worker-ca)\n"
    "    tokens                  the server's token table (hashes only)\n"
    "    worker.token            the workers' token (without --worker)\n"
    "    worker-NAME.token       a worker token for each --worker NAME\n"
    "    admin.token             an admin's token (sees every job)\n"
    "    NAME.token              a user's token for each --user NAME\n"
    "  --host NAME    a name or address clients give in --server (repeatable);\n"
    "                 default: localhost, 127.0.0.1 and this machine's host name\n"
    "  --user NAME    a user with a token of their own (repeatable)\n"
    "  --worker NAME  a worker token of its own for a machine or a Slurm array\n"
    "                 (repeatable): revoked alone, named in the log of its results\n"
    "  --days N       how long the certificates are valid (default 825)\n"
    "  Keys and tokens are created readable by their owner only. DIR must not\n"
    "  hold any of these files already.\n";

constexpr const char* kAddTokenUsage =
    "usage: mbopt-server add-token [ROLE NAME] --tokens FILE [--role worker|user|admin --name NAME] --out TOKEN_FILE\n"
    "  Makes a new token, writes it to TOKEN_FILE (created, mode 0600) and adds\n"
    "  its hash to the server's token table FILE. A running server reads the\n"
    "  table again on SIGHUP. Revoke a token by deleting its line. Each token\n"
    "  has a name of its own within its role (`add-token worker rack2 ...` for\n"
    "  a machine's workers), so one can be revoked without the others.\n";

struct InitTlsFlags {
  std::string dir;
  std::vector<std::string> hosts;
  std::vector<std::string> users;
  std::vector<std::string> workers;
  std::int64_t days = 825;
};

int Usage(const char* usage, const std::string& problem) {
  std::cerr << "mbopt-server: " << problem << "\n" << usage;
  return 2;
}

std::string HostName() {
  char name[HOST_NAME_MAX + 1] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return "";
  return name;
}

// The files of one installation, written in order; the first failure stops.
class Writer {
 public:
  explicit Writer(std::string dir) : dir_(std::move(dir)) {}
  bool Write(const std::string& name, const std::string& content, unsigned mode) {
    if (!status_.ok()) return false;
    status_ = WriteNewFile(dir_ + "/" + name, content, mode);
    if (status_.ok()) written_.push_back(name);
    return status_.ok();
  }
  const absl::Status& status() const { return status_; }
  const std::vector<std::string>& written() const { return written_; }

 private:
  std::string dir_;
  absl::Status status_;
  std::vector<std::string> written_;
};

bool ParseInitTlsFlags(int argc, char** argv, InitTlsFlags* flags, int* exit_code) {
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << kInitTlsUsage;
      *exit_code = 0;
      return false;
    }
    if (arg.rfind("--", 0) != 0) {
      if (!flags->dir.empty()) {
        *exit_code = Usage(kInitTlsUsage, "init-tls takes one directory, got '" + flags->dir + "' and '" + arg + "'");
        return false;
      }
      flags->dir = arg;
      continue;
    }
    std::string name, value;
    if (!FlagValue(argc, argv, &i, &name, &value)) {
      *exit_code = Usage(kInitTlsUsage, arg + " needs a value");
      return false;
    }
    if (name == "--host") {
      flags->hosts.push_back(value);
    } else if (name == "--user") {
      if (!auth::TokenTable::ValidName(value) || value == "worker" || value == "admin") {
        *exit_code = Usage(kInitTlsUsage, "--user takes a name of 1 to 64 of A-Z a-z 0-9 . _ @ - (not 'worker' or "
                                          "'admin'), got '" + value + "'");
        return false;
      }
      flags->users.push_back(value);
    } else if (name == "--worker") {
      if (!auth::TokenTable::ValidName(value)) {
        *exit_code = Usage(kInitTlsUsage, "--worker takes a name of 1 to 64 of A-Z a-z 0-9 . _ @ -, got '" + value + "'");
        return false;
      }
      if (std::find(flags->workers.begin(), flags->workers.end(), value) != flags->workers.end()) {
        *exit_code = Usage(kInitTlsUsage, "--worker '" + value + "' is given twice: each worker token has a name of its own");
        return false;
      }
      flags->workers.push_back(value);
    } else if (name == "--days") {
      if (!absl::SimpleAtoi(value, &flags->days) || flags->days < 1 || flags->days > 36500) {
        *exit_code = Usage(kInitTlsUsage, "--days needs a whole number of days from 1 to 36500, got '" + value + "'");
        return false;
      }
    } else {
      *exit_code = Usage(kInitTlsUsage, "unknown option '" + name + "'");
      return false;
    }
  }
  if (flags->dir.empty()) {
    *exit_code = Usage(kInitTlsUsage, "init-tls needs the directory to make");
    return false;
  }
  return true;
}

}  // namespace

int RunInitTlsCommand(int argc, char** argv) {
  InitTlsFlags flags;
  int exit_code = 0;
  if (!ParseInitTlsFlags(argc, argv, &flags, &exit_code)) return exit_code;
  if (flags.hosts.empty()) {
    flags.hosts = {"localhost", "127.0.0.1"};
    if (const std::string host = HostName(); !host.empty() && host != "localhost") flags.hosts.push_back(host);
  }
  if (::mkdir(flags.dir.c_str(), 0700) != 0 && errno != EEXIST) {
    std::cerr << "mbopt-server init-tls: cannot create " << flags.dir << ": " << std::strerror(errno) << "\n";
    return 1;
  }
  const std::int64_t valid_s = flags.days * 86400;
  auth::CertificateRequest ca_request{auth::CertificateKind::kAuthority, "mbopt certificate authority", {}, -3600,
                                      valid_s};
  absl::StatusOr<auth::KeyAndCertificate> ca = auth::MakeCertificate(ca_request, nullptr);
  absl::StatusOr<auth::KeyAndCertificate> server;
  absl::StatusOr<auth::KeyAndCertificate> worker;
  if (ca.ok()) {
    server = auth::MakeCertificate({auth::CertificateKind::kServer, "mbopt server", flags.hosts, -3600, valid_s}, &*ca);
    worker = auth::MakeCertificate({auth::CertificateKind::kClient, "mbopt worker", {}, -3600, valid_s}, &*ca);
  }
  for (const absl::Status& s : {ca.status(), server.status(), worker.status()}) {
    if (!s.ok()) {
      std::cerr << "mbopt-server init-tls: " << s.message() << "\n";
      return 1;
    }
  }
  struct Holder {
    auth::Principal principal;
    std::string file;
  };
  // One shared worker token, or one per --worker (a machine, a Slurm array):
  // those are revoked one by one and name who computed each result.
  std::vector<Holder> holders;
  if (flags.workers.empty()) holders.push_back({{auth::Role::kWorker, "workers"}, "worker.token"});
  for (const std::string& worker : flags.workers) {
    holders.push_back({{auth::Role::kWorker, worker}, "worker-" + worker + ".token"});
  }
  holders.push_back({{auth::Role::kAdmin, "admin"}, "admin.token"});
  for (const std::string& user : flags.users) holders.push_back({{auth::Role::kUser, user}, user + ".token"});
  std::string table = "# mbopt-server token table: ROLE NAME SHA256-OF-TOKEN (docs/server.md, \"Security\")\n";
  std::vector<std::string> tokens;
  for (const Holder& holder : holders) {
    absl::StatusOr<std::string> token = auth::NewToken();
    if (!token.ok()) {
      std::cerr << "mbopt-server init-tls: " << token.status().message() << "\n";
      return 1;
    }
    table += auth::TokenTable::Line(holder.principal, *token);
    tokens.push_back(*token + "\n");
  }

  Writer writer(flags.dir);
  writer.Write("ca.key", ca->key_pem, 0600);
  writer.Write("ca.pem", ca->certificate_pem, 0644);
  writer.Write("server.key", server->key_pem, 0600);
  writer.Write("server.pem", server->certificate_pem, 0644);
  writer.Write("worker.key", worker->key_pem, 0600);
  writer.Write("worker.pem", worker->certificate_pem, 0644);
  for (std::size_t i = 0; i < holders.size(); ++i) writer.Write(holders[i].file, tokens[i], 0600);
  writer.Write("tokens", table, 0600);
  if (!writer.status().ok()) {
    std::cerr << "mbopt-server init-tls: " << writer.status().message();
    if (!writer.written().empty()) std::cerr << " (made before it: " << absl::StrJoin(writer.written(), ", ") << ")";
    std::cerr << "\n";
    return 1;
  }
  const std::string dir = std::filesystem::absolute(flags.dir).lexically_normal().string();
  const std::string host = flags.hosts.back();
  std::cout << "made " << dir << ": a CA, a server certificate for " << absl::StrJoin(flags.hosts, ", ")
            << " (valid " << flags.days << " days), a worker certificate, and tokens for the workers"
            << (flags.workers.empty() ? "" : " (" + absl::StrJoin(flags.workers, ", ") + ")") << ", an admin"
            << (flags.users.empty() ? "" : " and " + absl::StrJoin(flags.users, ", ")) << ".\n"
            << "Keep ca.key where only you can read it: renew-cert needs it, and whoever has it can make\n"
            << "certificates this installation trusts.\n\n"
            << "server:  mbopt-server --listen 0.0.0.0:50051 --tls-dir " << dir << "\n"
            << "           (add --worker-ca " << dir << "/ca.pem to require worker certificates)\n"
            << "worker:  mbopt-worker --server " << host << ":50051 --tls-ca " << dir << "/ca.pem --token-file "
            << dir << "/" << holders.front().file
            << (flags.workers.size() > 1 ? "   (each machine its own worker-NAME.token)" : "") << "\n"
            << "           (with --tls-cert " << dir << "/worker.pem --tls-key " << dir << "/worker.key)\n"
            << "client:  export MBOPT_SERVER=" << host << ":50051 MBOPT_TLS_CA=" << dir << "/ca.pem MBOPT_TOKEN_FILE="
            << dir << "/" << holders.back().file << "\n"
            << "         mbopt submit STUDY --watch\n"
            << "Copy ca.pem and a token file to each machine that connects; never the keys of others.\n";
  return 0;
}

int RunAddTokenCommand(int argc, char** argv) {
  std::string tokens_path, role_name, name, out;
  std::vector<std::string> positional;
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << kAddTokenUsage;
      return 0;
    }
    if (arg.rfind("--", 0) != 0) {
      positional.push_back(arg);
      continue;
    }
    std::string option, value;
    if (!FlagValue(argc, argv, &i, &option, &value)) return Usage(kAddTokenUsage, arg + " needs a value");
    if (option == "--tokens") {
      tokens_path = value;
    } else if (option == "--role") {
      role_name = value;
    } else if (option == "--name") {
      name = value;
    } else if (option == "--out") {
      out = value;
    } else {
      return Usage(kAddTokenUsage, "unknown option '" + option + "'");
    }
  }
  if (!positional.empty()) {
    if (positional.size() != 2 || !role_name.empty() || !name.empty()) {
      return Usage(kAddTokenUsage, "add-token takes a role and a name, as `add-token worker NAME` or with --role "
                                   "and --name, not both");
    }
    role_name = positional[0];
    name = positional[1];
  }
  if (tokens_path.empty() || role_name.empty() || name.empty() || out.empty()) {
    return Usage(kAddTokenUsage, "add-token needs --tokens, --role, --name and --out");
  }
  const std::optional<auth::Role> role = auth::ParseRole(role_name);
  if (!role) return Usage(kAddTokenUsage, "--role is worker, user or admin, got '" + role_name + "'");
  if (!auth::TokenTable::ValidName(name)) {
    return Usage(kAddTokenUsage, "--name is 1 to 64 of A-Z a-z 0-9 . _ @ -, got '" + name + "'");
  }
  if (std::error_code ec; std::filesystem::exists(tokens_path, ec)) {
    absl::StatusOr<auth::TokenTable> table = auth::TokenTable::Load(tokens_path);
    if (!table.ok()) {
      std::cerr << "mbopt-server add-token: " << table.status().message() << "\n";
      return 1;
    }
    // Revoking is deleting a holder's line; a second token of the same name
    // would survive it and keep that holder's workers in (server.cc).
    if (table->HasHolder({*role, name})) {
      std::cerr << "mbopt-server add-token: " << tokens_path << " already has a " << role_name << " token named '"
                << name << "': give this one a name of its own, so that each can be revoked alone\n";
      return 1;
    }
  }
  absl::StatusOr<std::string> token = auth::NewToken();
  absl::Status status = token.status();
  if (status.ok()) status = WriteNewFile(out, *token + "\n", 0600);
  if (status.ok()) status = AppendToFile(tokens_path, auth::TokenTable::Line({*role, name}, *token));
  if (!status.ok()) {
    std::cerr << "mbopt-server add-token: " << status.message() << "\n";
    return 1;
  }
  std::cout << "wrote a " << role_name << " token for '" << name << "' to " << out << " and its hash to "
            << tokens_path << "; a running server takes it on SIGHUP (or its next start)\n";
  return 0;
}

}  // namespace mbopt::server_main
