// FMUs that travel with their study (spec::FmuModel::archive), unpacked once
// per content on each machine instead of once per analysis: the folder
// `<cache>/<sha256>` holds the archive whose bytes have that SHA-256, and
// every analysis of any study carrying the same bytes opens it from there
// (Fmu::OpenUnpacked).
//
// The cache is `<temp dir>/mbopt-fmu-cache-<uid>`, mode 0700, shared by the
// user's workers on the machine; one owned by another user is refused. An
// archive is unpacked into a fresh folder of the cache and renamed to its
// hash only when complete, so a folder under a hash is always whole, and
// processes or threads unpacking the same bytes at once agree on one folder
// (the rename of the later one fails and its copy is removed). The hash is
// the one spec/io computed from the bytes where the study was converted, in
// this process: never a name taken from the wire. Folders stay until the
// cache is removed (safe whenever no worker of the user runs).
#pragma once

#include <filesystem>
#include <string>

#include "absl/status/statusor.h"

namespace mbopt::fmu {

// `<temp dir>/mbopt-fmu-cache-<uid>`.
std::filesystem::path DefaultArchiveCacheDirectory();

// The folder holding the archive `bytes` unpacked, `cache/<sha256>`, made
// now if it is not there yet (the cache too, 0700). `archive_path` names
// the archive in messages. Errors of Unpack (unsafe entries, not a zip)
// name it.
absl::StatusOr<std::filesystem::path> UnpackedArchiveFolder(const std::string& bytes, const std::string& sha256,
                                                            const std::string& archive_path,
                                                            const std::filesystem::path& cache =
                                                                DefaultArchiveCacheDirectory());

}  // namespace mbopt::fmu
