#include "server/main/renew_cert_command.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "common/read_file.h"
#include "server/auth/certificates.h"
#include "server/main/flag_value.h"
#include "server/main/secret_file.h"

namespace mbopt::server_main {
namespace {

constexpr const char* kUsage =
    "usage: mbopt-server renew-cert DIR [--host NAME]... [--days N]\n"
    "  Makes a new server certificate and key in DIR, an init-tls directory,\n"
    "  signed by its CA (DIR/ca.pem, DIR/ca.key): clients and workers keep\n"
    "  their ca.pem and tokens. The old certificate and key are kept as\n"
    "  server.pem.old and server.key.old. Restart the server to use the new one.\n"
    "  --host NAME  the names and addresses (repeatable); default: those of the\n"
    "               current certificate\n"
    "  --days N     validity (default 825)\n";

bool ReadFile(const std::string& path, std::string* out) {
  absl::StatusOr<std::string> text = ReadWholeFile(path);
  if (!text.ok()) return false;
  *out = *std::move(text);
  return true;
}

int Fail(const std::string& message) {
  std::cerr << "mbopt-server renew-cert: " << message << "\n";
  return 1;
}

}  // namespace

int RunRenewCertCommand(int argc, char** argv) {
  std::string dir;
  std::vector<std::string> hosts;
  std::int64_t days = 825;
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      return 0;
    }
    if (arg.rfind("--", 0) != 0) {
      if (!dir.empty()) {
        std::cerr << "mbopt-server: renew-cert takes one directory\n" << kUsage;
        return 2;
      }
      dir = arg;
      continue;
    }
    std::string name, value;
    if (!FlagValue(argc, argv, &i, &name, &value)) {
      std::cerr << "mbopt-server: " << arg << " needs a value\n" << kUsage;
      return 2;
    }
    if (name == "--host") {
      hosts.push_back(value);
    } else if (name == "--days" && absl::SimpleAtoi(value, &days) && days >= 1 && days <= 36500) {
    } else {
      std::cerr << "mbopt-server: bad option '" << arg << "'\n" << kUsage;
      return 2;
    }
  }
  if (dir.empty()) {
    std::cerr << "mbopt-server: renew-cert needs the init-tls directory\n" << kUsage;
    return 2;
  }
  auth::KeyAndCertificate ca;
  std::string old_certificate, old_key;
  if (!ReadFile(dir + "/ca.pem", &ca.certificate_pem) || !ReadFile(dir + "/ca.key", &ca.key_pem)) {
    return Fail(absl::StrCat("cannot read ", dir, "/ca.pem and ", dir, "/ca.key (the CA init-tls made)"));
  }
  if (!ReadFile(dir + "/server.pem", &old_certificate) || !ReadFile(dir + "/server.key", &old_key)) {
    return Fail(absl::StrCat("cannot read ", dir, "/server.pem and ", dir, "/server.key"));
  }
  if (hosts.empty()) {
    absl::StatusOr<auth::CertificateInfo> old = auth::InspectCertificate(old_certificate, dir + "/server.pem");
    if (!old.ok()) return Fail(std::string(old.status().message()));
    hosts = old->hosts;
  }
  absl::StatusOr<auth::KeyAndCertificate> made =
      auth::MakeCertificate({auth::CertificateKind::kServer, "mbopt server", hosts, -3600, days * 86400}, &ca);
  if (!made.ok()) return Fail(std::string(made.status().message()));
  // The new files first, then the old ones kept, then the new ones in place:
  // whatever stops this midway leaves a certificate and its key together.
  const std::string pem = dir + "/server.pem", key = dir + "/server.key";
  std::remove((pem + ".new").c_str());
  std::remove((key + ".new").c_str());
  absl::Status status = WriteNewFile(pem + ".new", made->certificate_pem, 0644);
  if (status.ok()) status = WriteNewFile(key + ".new", made->key_pem, 0600);
  if (!status.ok()) return Fail(std::string(status.message()));
  for (const std::string& path : {pem, key}) {
    std::remove((path + ".old").c_str());
    if (std::rename(path.c_str(), (path + ".old").c_str()) != 0 ||
        std::rename((path + ".new").c_str(), path.c_str()) != 0) {
      return Fail(absl::StrCat("cannot replace ", path, ": ", std::strerror(errno)));
    }
  }
  std::cout << "renewed " << pem << " for " << absl::StrJoin(hosts, ", ") << " (valid " << days
            << " days); the old certificate is " << pem << ".old. Restart the server to use it.\n";
  return 0;
}

}  // namespace mbopt::server_main
