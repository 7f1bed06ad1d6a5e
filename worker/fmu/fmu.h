// An FMI 2.0 or 3.0 FMU opened for one interface type: its archive unpacked
// into a private folder, its model description read and its binary for this
// platform loaded. One Fmu runs any number of simulations one after the
// other (each instantiates the model afresh); it is not thread-safe.
//
// Errors of Open are InvalidArgument naming the archive and what is wrong
// with it: no modelDescription.xml, no binary for this platform (with the
// platforms it has), the interface type not offered, a function missing.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <variant>

#include "absl/status/statusor.h"
#include "worker/fmu/fmi2_library.h"
#include "worker/fmu/fmi3_library.h"
#include "worker/fmu/fmu_archive.h"
#include "worker/fmu/model_description.h"

namespace mbopt::fmu {

// The platform folder of binaries this build loads: FMI 2.0 names it
// "linux64" on 64-bit Linux, FMI 3.0 by a tuple such as "x86_64-linux".
// "" where the version names no platform for this build.
const char* ThisPlatform(int fmi_major_version = 2);

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
  // A new instance of the model, of this FMU's FMI version; see
  // ModelInstance::instantiated() for whether the FMU made it.
  std::unique_ptr<ModelInstance> Instantiate() const;
  // Whether the binary exports fmi2/fmi3GetDirectionalDerivative.
  bool exports_directional_derivative() const;
  const std::filesystem::path& archive_path() const { return archive_.archive_path(); }

 private:
  using Library = std::variant<Fmi2Library, Fmi3Library>;

  static absl::StatusOr<Fmu> Load(UnpackedArchive archive, Interface interface);

  // `resource_location`: the unpacked resources folder as the FMU's
  // version wants it (a file:// URI for 2.0, a path ending in '/' for 3.0).
  Fmu(UnpackedArchive archive, ModelDescription description, Library library, Interface interface,
      std::string resource_location)
      : archive_(std::move(archive)),
        description_(std::move(description)),
        library_(std::move(library)),
        interface_(interface),
        resource_location_(std::move(resource_location)) {}

  // Declared first so that the library is closed before its folder goes.
  UnpackedArchive archive_;
  ModelDescription description_;
  Library library_;
  Interface interface_;
  std::string resource_location_;
};

}  // namespace mbopt::fmu
