// An FMI 2.0 FMU opened for one interface type: its archive unpacked into a
// private folder, its model description read and its binary for this
// platform loaded. One Fmu runs any number of simulations one after the
// other (each instantiates the model afresh); it is not thread-safe.
//
// Errors of Open are InvalidArgument naming the archive and what is wrong
// with it: no modelDescription.xml, no binary for this platform (with the
// platforms it has), the interface type not offered, a function missing.
#pragma once

#include <filesystem>
#include <string>

#include "absl/status/statusor.h"
#include "worker/fmu/fmi2_library.h"
#include "worker/fmu/fmu_archive.h"
#include "worker/fmu/model_description.h"

namespace mbopt::fmu {

// The FMI platform folder of binaries this build loads ("linux64" on 64-bit
// Linux), or "" where FMI names no platform for this build.
const char* ThisPlatform();

class Fmu {
 public:
  static absl::StatusOr<Fmu> Open(const std::filesystem::path& archive_path, Interface interface,
                                  const std::filesystem::path& temporary_parent = {});
  // The same from an archive unpacked earlier into `folder` (a study's
  // carried FMU in the worker's cache, archive_cache.h), which stays when
  // the Fmu goes; `archive_path` names it in messages.
  static absl::StatusOr<Fmu> OpenUnpacked(const std::filesystem::path& archive_path,
                                          const std::filesystem::path& folder, Interface interface);

  Interface interface() const { return interface_; }
  const ModelDescription& description() const { return description_; }
  const InterfaceType& interface_type() const {
    return interface_ == Interface::kModelExchange ? *description_.model_exchange : *description_.co_simulation;
  }
  const Fmi2Functions& functions() const { return library_.functions(); }
  // The file:// URI of the unpacked resources folder, for fmi2Instantiate.
  const std::string& resource_uri() const { return resource_uri_; }
  const std::filesystem::path& archive_path() const { return archive_.archive_path(); }

 private:
  static absl::StatusOr<Fmu> Load(UnpackedArchive archive, Interface interface);
  Fmu(UnpackedArchive archive, ModelDescription description, Fmi2Library library, Interface interface,
      std::string resource_uri)
      : archive_(std::move(archive)),
        description_(std::move(description)),
        library_(std::move(library)),
        interface_(interface),
        resource_uri_(std::move(resource_uri)) {}

  // Declared first so that the library is closed before its folder goes.
  UnpackedArchive archive_;
  ModelDescription description_;
  Fmi2Library library_;
  Interface interface_;
  std::string resource_uri_;
};

}  // namespace mbopt::fmu
