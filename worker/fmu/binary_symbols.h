// Opening an FMU's shared library and finding its functions: the same for
// every FMI version (fmi2_library.cc, fmi3_library.cc).
#pragma once

#include <dlfcn.h>

#include <filesystem>
#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"

namespace mbopt::fmu {

// An opened shared library, closed when the last owner goes; move-only so
// the functions resolved from it never outlive it by a copy.
class OpenedBinary {
 public:
  OpenedBinary() = default;
  explicit OpenedBinary(void* handle) : handle_(handle) {}
  OpenedBinary(OpenedBinary&& other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
  OpenedBinary& operator=(OpenedBinary&& other) noexcept {
    if (this != &other) {
      Close();
      handle_ = std::exchange(other.handle_, nullptr);
    }
    return *this;
  }
  OpenedBinary(const OpenedBinary&) = delete;
  OpenedBinary& operator=(const OpenedBinary&) = delete;
  ~OpenedBinary() { Close(); }

  void* handle() const { return handle_; }

 private:
  void Close() {
    if (handle_ != nullptr) dlclose(handle_);
    handle_ = nullptr;
  }

  void* handle_ = nullptr;
};

// `binary` opened with RTLD_LOCAL (two FMUs exporting the same names do not
// see each other), or InvalidArgument naming it.
inline absl::StatusOr<OpenedBinary> OpenBinary(const std::filesystem::path& binary) {
  void* handle = dlopen(binary.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* reason = dlerror();
    return absl::InvalidArgumentError(
        absl::StrCat(binary.string(), ": the FMU's binary cannot be loaded: ", reason ? reason : "unknown"));
  }
  return OpenedBinary(handle);
}

// Sets `*out` to the function `name` of the opened binary (null when it has
// none); InvalidArgument naming the binary and the function when a
// `required` one is missing.
template <typename Function>
absl::Status ResolveFunction(void* handle, const std::filesystem::path& binary, const char* name, Function** out,
                             bool required = true) {
  dlerror();
  void* symbol = dlsym(handle, name);
  if (symbol == nullptr && required) {
    return absl::InvalidArgumentError(absl::StrCat(binary.string(), ": the FMU's binary has no function ", name));
  }
  *out = reinterpret_cast<Function*>(symbol);
  return absl::OkStatus();
}

}  // namespace mbopt::fmu
