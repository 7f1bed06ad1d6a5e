#include "spec/io/fmu_archive_contents.h"

#include <openssl/evp.h>
#include <zip.h>

#include <fstream>
#include <memory>
#include <set>
#include <system_error>
#include <utility>

#include "absl/strings/str_cat.h"
#include "spec/limits.h"

namespace mbopt::spec::io {
namespace {

struct ZipDiscard {
  void operator()(zip_t* archive) const { zip_discard(archive); }
};

std::string Sha256Hex(const std::string& bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int size = 0;
  EVP_Digest(bytes.data(), bytes.size(), digest, &size, EVP_sha256(), nullptr);
  static const char kHex[] = "0123456789abcdef";
  std::string hex;
  for (unsigned int i = 0; i < size; ++i) {
    hex.push_back(kHex[digest[i] >> 4]);
    hex.push_back(kHex[digest[i] & 15]);
  }
  return hex;
}

}  // namespace

absl::StatusOr<std::string> ReadFmuArchive(const std::filesystem::path& path) {
  std::error_code code;
  const std::uintmax_t size = std::filesystem::file_size(path, code);
  if (code) return absl::InvalidArgumentError(absl::StrCat(path.string(), ": cannot be read: ", code.message()));
  if (size > static_cast<std::uintmax_t>(kMaxFmuArchiveBytes)) {
    return absl::InvalidArgumentError(absl::StrCat(path.string(), ": ", size, " bytes; an FMU a study carries may have ",
                                                   kMaxFmuArchiveBytes >> 20, " MiB at most"));
  }
  std::ifstream in(path, std::ios::binary);
  std::string bytes(static_cast<size_t>(size), '\0');
  if (!in.read(bytes.data(), static_cast<std::streamsize>(size))) {
    return absl::InvalidArgumentError(absl::StrCat(path.string(), ": cannot be read"));
  }
  return bytes;
}

absl::StatusOr<FmuArchiveContents> ReadFmuArchiveContents(const std::string& bytes) {
  zip_error_t error;
  zip_error_init(&error);
  zip_source_t* source = zip_source_buffer_create(bytes.data(), bytes.size(), 0, &error);
  if (source == nullptr) {
    const std::string reason = zip_error_strerror(&error);
    zip_error_fini(&error);
    return absl::InternalError(absl::StrCat("cannot read the FMU's bytes: ", reason));
  }
  std::unique_ptr<zip_t, ZipDiscard> archive(zip_open_from_source(source, ZIP_RDONLY, &error));
  if (archive == nullptr) {
    zip_source_free(source);
    const std::string reason = zip_error_strerror(&error);
    zip_error_fini(&error);
    return absl::InvalidArgumentError(absl::StrCat("not an FMU (zip) archive: ", reason));
  }
  zip_error_fini(&error);
  std::set<std::string> platforms;
  const std::string prefix = "binaries/";
  const zip_int64_t count = zip_get_num_entries(archive.get(), 0);
  for (zip_int64_t i = 0; i < count; ++i) {
    const char* raw = zip_get_name(archive.get(), static_cast<zip_uint64_t>(i), 0);
    if (raw == nullptr) continue;
    const std::string name = raw;
    if (name.rfind(prefix, 0) != 0) continue;
    const size_t end = name.find('/', prefix.size());
    // A platform is a folder holding a file: "binaries/linux64/" alone is none.
    if (end != std::string::npos && end > prefix.size() && end + 1 < name.size()) {
      platforms.insert(name.substr(prefix.size(), end - prefix.size()));
    }
  }
  // Workers announce the platform by its FMI 2.0 name (linux64); FMI 3.0
  // names the same machines otherwise, so an FMI 3.0 binary for them
  // counts under both names.
  for (const auto& [fmi3_name, fmi2_name] : {std::pair{"x86_64-linux", "linux64"}, std::pair{"x86-linux", "linux32"}}) {
    if (platforms.count(fmi3_name) != 0) platforms.insert(fmi2_name);
  }
  FmuArchiveContents contents;
  contents.sha256 = Sha256Hex(bytes);
  contents.platforms.assign(platforms.begin(), platforms.end());
  return contents;
}

}  // namespace mbopt::spec::io
