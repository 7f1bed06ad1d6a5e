#include "worker/fmu/fmu_archive.h"

#include <stdlib.h>
#include <sys/stat.h>
#include <zip.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <memory>
#include <system_error>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"

namespace mbopt::fmu {
namespace {

struct ZipClose {
  void operator()(zip_t* archive) const { zip_discard(archive); }
};
struct ZipFileClose {
  void operator()(zip_file_t* file) const { zip_fclose(file); }
};

// Entries larger than this are refused: an FMU is a model, not a data set,
// and a zip bomb would otherwise fill the worker's disk.
constexpr zip_uint64_t kMaxEntryBytes = zip_uint64_t{1} << 30;

bool IsSymbolicLink(zip_t* archive, zip_uint64_t index) {
  zip_uint8_t system = 0;
  zip_uint32_t attributes = 0;
  if (zip_file_get_external_attributes(archive, index, 0, &system, &attributes) != 0) return false;
  // Unix zips keep the st_mode in the high 16 bits.
  return system == ZIP_OPSYS_UNIX && S_ISLNK(attributes >> 16);
}

absl::Status ExtractEntry(zip_t* archive, zip_uint64_t index, const std::string& name,
                          const std::filesystem::path& target, const std::filesystem::path& archive_path) {
  zip_stat_t stat;
  zip_stat_init(&stat);
  if (zip_stat_index(archive, index, 0, &stat) != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(archive_path.string(), ": entry ", name, ": cannot be read: ", zip_strerror(archive)));
  }
  if ((stat.valid & ZIP_STAT_SIZE) != 0 && stat.size > kMaxEntryBytes) {
    return absl::InvalidArgumentError(absl::StrCat(archive_path.string(), ": entry ", name, ": ", stat.size,
                                                   " bytes, more than the ", kMaxEntryBytes, " an FMU entry may have"));
  }
  std::unique_ptr<zip_file_t, ZipFileClose> file(zip_fopen_index(archive, index, 0));
  if (file == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat(archive_path.string(), ": entry ", name, ": cannot be opened: ", zip_strerror(archive)));
  }
  std::ofstream out(target, std::ios::binary | std::ios::trunc);
  if (!out) return absl::InternalError(absl::StrCat("cannot write ", target.string()));
  char buffer[1 << 16];
  zip_uint64_t total = 0;
  while (true) {
    const zip_int64_t read = zip_fread(file.get(), buffer, sizeof buffer);
    if (read < 0) {
      return absl::InvalidArgumentError(absl::StrCat(archive_path.string(), ": entry ", name,
                                                     ": corrupt: ", zip_file_strerror(file.get())));
    }
    if (read == 0) break;
    total += static_cast<zip_uint64_t>(read);
    if (total > kMaxEntryBytes) {
      return absl::InvalidArgumentError(absl::StrCat(archive_path.string(), ": entry ", name,
                                                     ": more than the ", kMaxEntryBytes, " bytes an FMU entry may have"));
    }
    out.write(buffer, read);
  }
  if (!out.flush()) return absl::InternalError(absl::StrCat("cannot write ", target.string()));
  return absl::OkStatus();
}

}  // namespace

bool IsSafeEntryName(const std::string& name) {
  if (name.empty() || name.front() == '/' || name.find('\\') != std::string::npos) return false;
  for (const absl::string_view part : absl::StrSplit(name, '/')) {
    if (part == "..") return false;
  }
  return true;
}

absl::StatusOr<UnpackedArchive> UnpackedArchive::Unpack(const std::filesystem::path& archive_path,
                                                        const std::filesystem::path& temporary_parent) {
  int error = 0;
  std::unique_ptr<zip_t, ZipClose> archive(zip_open(archive_path.c_str(), ZIP_RDONLY, &error));
  if (archive == nullptr) {
    zip_error_t zip_error;
    zip_error_init_with_code(&zip_error, error);
    const std::string reason = zip_error_strerror(&zip_error);
    zip_error_fini(&zip_error);
    return absl::InvalidArgumentError(
        absl::StrCat(archive_path.string(), ": not a readable FMU (zip) archive: ", reason));
  }

  std::error_code code;
  const std::filesystem::path parent =
      temporary_parent.empty() ? std::filesystem::temp_directory_path(code) : temporary_parent;
  if (code) return absl::InternalError(absl::StrCat("no temporary folder: ", code.message()));
  std::string pattern = (parent / "mbopt-fmu-XXXXXX").string();
  if (mkdtemp(pattern.data()) == nullptr) {
    return absl::InternalError(absl::StrCat("cannot make a folder like ", pattern, ": ", std::strerror(errno)));
  }
  UnpackedArchive unpacked(archive_path, pattern);

  const zip_int64_t count = zip_get_num_entries(archive.get(), 0);
  for (zip_int64_t i = 0; i < count; ++i) {
    const auto index = static_cast<zip_uint64_t>(i);
    const char* raw_name = zip_get_name(archive.get(), index, 0);
    if (raw_name == nullptr) {
      return absl::InvalidArgumentError(
          absl::StrCat(archive_path.string(), ": entry ", i, " has no readable name: ", zip_strerror(archive.get())));
    }
    const std::string name = raw_name;
    if (!IsSafeEntryName(name)) {
      return absl::InvalidArgumentError(
          absl::StrCat(archive_path.string(), ": entry \"", name,
                       "\" would be written outside the FMU's folder (absolute, `..` or backslash); refused"));
    }
    if (IsSymbolicLink(archive.get(), index)) {
      return absl::InvalidArgumentError(
          absl::StrCat(archive_path.string(), ": entry \"", name, "\" is a symbolic link; an FMU's entries are "
                       "files and folders only"));
    }
    unpacked.entries_.push_back(name);
    const std::filesystem::path target = unpacked.folder_ / name;
    if (name.back() == '/') {
      std::filesystem::create_directories(target, code);
    } else {
      std::filesystem::create_directories(target.parent_path(), code);
    }
    if (code) return absl::InternalError(absl::StrCat("cannot make ", target.string(), ": ", code.message()));
    if (name.back() == '/') continue;
    if (absl::Status status = ExtractEntry(archive.get(), index, name, target, archive_path); !status.ok()) {
      return status;
    }
  }
  return unpacked;
}

absl::StatusOr<UnpackedArchive> UnpackedArchive::Borrow(const std::filesystem::path& archive_path,
                                                        const std::filesystem::path& folder) {
  std::error_code code;
  if (!std::filesystem::is_directory(folder, code)) {
    return absl::InternalError(absl::StrCat(archive_path.string(), ": no unpacked folder ", folder.string()));
  }
  UnpackedArchive borrowed(archive_path, folder);
  borrowed.owned_ = false;
  // The entry names as the archive had them: files, and folders with '/'.
  for (auto it = std::filesystem::recursive_directory_iterator(folder, code);
       !code && it != std::filesystem::recursive_directory_iterator(); it.increment(code)) {
    std::string name = it->path().lexically_relative(folder).generic_string();
    if (it->is_directory(code)) name += '/';
    borrowed.entries_.push_back(std::move(name));
  }
  if (code) return absl::InternalError(absl::StrCat("cannot list ", folder.string(), ": ", code.message()));
  std::sort(borrowed.entries_.begin(), borrowed.entries_.end());
  return borrowed;
}

UnpackedArchive::UnpackedArchive(UnpackedArchive&& other) noexcept
    : archive_path_(std::move(other.archive_path_)),
      folder_(std::move(other.folder_)),
      entries_(std::move(other.entries_)),
      owned_(other.owned_) {
  other.folder_.clear();
}

UnpackedArchive& UnpackedArchive::operator=(UnpackedArchive&& other) noexcept {
  if (this != &other) {
    std::error_code ignored;
    if (owned_ && !folder_.empty()) std::filesystem::remove_all(folder_, ignored);
    archive_path_ = std::move(other.archive_path_);
    folder_ = std::move(other.folder_);
    entries_ = std::move(other.entries_);
    owned_ = other.owned_;
    other.folder_.clear();
  }
  return *this;
}

UnpackedArchive::~UnpackedArchive() {
  std::error_code ignored;
  if (owned_ && !folder_.empty()) std::filesystem::remove_all(folder_, ignored);
}

}  // namespace mbopt::fmu
