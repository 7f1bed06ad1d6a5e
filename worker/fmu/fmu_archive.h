// An FMU archive (.fmu, a zip file) unpacked into a private temporary folder
// that lives as long as the UnpackedArchive object: the binary is loaded
// from there and the model finds its resources there.
//
// Entries that could write outside the folder are refused, not skipped:
// absolute names, names with a `..` component, and symbolic links (the
// unpacker writes regular files and folders only, so no link inside the
// folder can lead out of it). Errors name the archive and the entry.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace mbopt::fmu {

class UnpackedArchive {
 public:
  // Unpacks `archive_path` into a new folder under `temporary_parent` (the
  // system's temporary folder when empty).
  static absl::StatusOr<UnpackedArchive> Unpack(const std::filesystem::path& archive_path,
                                                const std::filesystem::path& temporary_parent = {});
  // An archive unpacked earlier into `folder` (archive_cache.h), which this
  // object neither owns nor removes; `archive_path` names it in messages.
  static absl::StatusOr<UnpackedArchive> Borrow(const std::filesystem::path& archive_path,
                                                const std::filesystem::path& folder);

  UnpackedArchive(UnpackedArchive&& other) noexcept;
  UnpackedArchive& operator=(UnpackedArchive&& other) noexcept;
  UnpackedArchive(const UnpackedArchive&) = delete;
  UnpackedArchive& operator=(const UnpackedArchive&) = delete;
  ~UnpackedArchive();  // removes the folder, unless borrowed

  const std::filesystem::path& archive_path() const { return archive_path_; }
  const std::filesystem::path& folder() const { return folder_; }
  // The archive's entry names, in archive order.
  const std::vector<std::string>& entries() const { return entries_; }

 private:
  UnpackedArchive(std::filesystem::path archive_path, std::filesystem::path folder)
      : archive_path_(std::move(archive_path)), folder_(std::move(folder)) {}

  std::filesystem::path archive_path_;
  std::filesystem::path folder_;
  std::vector<std::string> entries_;
  bool owned_ = true;
};

// Whether a zip entry name stays inside the folder it is unpacked into:
// relative, no `..` component, no backslash (a separator on other systems).
bool IsSafeEntryName(const std::string& name);

}  // namespace mbopt::fmu
