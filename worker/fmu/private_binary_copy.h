// FMUs that declare canBeInstantiatedOnlyOncePerProcess keep an instance's
// state in their library's globals. The dynamic loader maps one file once
// per process, so a worker running such an FMU on several slots gives each
// load a copy of the binary of its own: beside the original (libraries it
// finds through $ORIGIN still resolve), removed once loaded (the mapping
// stays).
#pragma once

#include <filesystem>

#include "absl/status/statusor.h"

namespace mbopt::fmu {

class PrivateBinaryCopy {
 public:
  // A fresh copy of `binary` in its folder; an error names the binary and
  // why the copy could not be made.
  static absl::StatusOr<PrivateBinaryCopy> Make(const std::filesystem::path& binary);

  PrivateBinaryCopy(PrivateBinaryCopy&& other) noexcept;
  PrivateBinaryCopy& operator=(PrivateBinaryCopy&&) = delete;
  PrivateBinaryCopy(const PrivateBinaryCopy&) = delete;
  PrivateBinaryCopy& operator=(const PrivateBinaryCopy&) = delete;
  ~PrivateBinaryCopy();  // removes the copy

  const std::filesystem::path& path() const { return path_; }

 private:
  explicit PrivateBinaryCopy(std::filesystem::path path) : path_(std::move(path)) {}

  std::filesystem::path path_;
};

}  // namespace mbopt::fmu
