#include "worker/fmu/archive_cache.h"

#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <system_error>

#include "absl/strings/str_cat.h"
#include "worker/fmu/fmu_archive.h"

namespace mbopt::fmu {
namespace {

// The cache made if missing; refused unless it is this user's own folder and
// no one else may write into it (a folder under a hash is trusted whole).
absl::Status EnsurePrivateFolder(const std::filesystem::path& cache) {
  if (mkdir(cache.c_str(), 0700) != 0 && errno != EEXIST) {
    return absl::InternalError(absl::StrCat("cannot make the FMU cache ", cache.string(), ": ", std::strerror(errno)));
  }
  struct stat st {};
  if (lstat(cache.c_str(), &st) != 0) {
    return absl::InternalError(absl::StrCat("cannot read the FMU cache ", cache.string(), ": ", std::strerror(errno)));
  }
  if (!S_ISDIR(st.st_mode) || st.st_uid != geteuid() || (st.st_mode & 0077) != 0) {
    return absl::FailedPreconditionError(
        absl::StrCat("the FMU cache ", cache.string(),
                     " is not a folder of this user's that only this user may use (mode 0700); remove it"));
  }
  return absl::OkStatus();
}

}  // namespace

std::filesystem::path DefaultArchiveCacheDirectory() {
  std::error_code code;
  std::filesystem::path temp = std::filesystem::temp_directory_path(code);
  if (code) temp = "/tmp";
  return temp / absl::StrCat("mbopt-fmu-cache-", geteuid());
}

absl::StatusOr<std::filesystem::path> UnpackedArchiveFolder(const std::string& bytes, const std::string& sha256,
                                                            const std::string& archive_path,
                                                            const std::filesystem::path& cache) {
  if (sha256.size() != 64 || sha256.find_first_not_of("0123456789abcdef") != std::string::npos) {
    return absl::InternalError(absl::StrCat(archive_path, ": \"", sha256, "\" is no SHA-256 in hex"));
  }
  if (absl::Status status = EnsurePrivateFolder(cache); !status.ok()) return status;
  const std::filesystem::path folder = cache / sha256;
  std::error_code code;
  if (std::filesystem::is_directory(folder, code)) return folder;

  // libzip reads a file: the bytes go to one of the cache's own, removed
  // once unpacked.
  std::string file_pattern = (cache / "incoming-XXXXXX").string();
  const int fd = mkstemp(file_pattern.data());
  if (fd < 0) {
    return absl::InternalError(absl::StrCat("cannot make a file like ", file_pattern, ": ", std::strerror(errno)));
  }
  close(fd);
  const std::filesystem::path incoming = file_pattern;
  {
    std::ofstream out(incoming, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out.flush()) {
      std::filesystem::remove(incoming, code);
      return absl::InternalError(absl::StrCat("cannot write ", incoming.string()));
    }
  }
  absl::StatusOr<UnpackedArchive> unpacked = UnpackedArchive::Unpack(incoming, cache);
  std::filesystem::remove(incoming, code);
  if (!unpacked.ok()) {
    // Unpack names the file it read; the user knows the archive by its path.
    std::string message(unpacked.status().message());
    if (message.rfind(incoming.string(), 0) == 0) message = archive_path + message.substr(incoming.string().size());
    return absl::Status(unpacked.status().code(), message);
  }
  // Whole now: give it its name. Should another process or thread have
  // been quicker, its folder stands and this one goes with `unpacked`.
  if (rename(unpacked->folder().c_str(), folder.c_str()) != 0 && errno != EEXIST && errno != ENOTEMPTY) {
    return absl::InternalError(
        absl::StrCat("cannot move the unpacked FMU to ", folder.string(), ": ", std::strerror(errno)));
  }
  return folder;
}

}  // namespace mbopt::fmu
