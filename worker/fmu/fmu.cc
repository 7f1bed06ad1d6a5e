#include "worker/fmu/fmu.h"

#include <fstream>
#include <optional>
#include <set>
#include <sstream>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_replace.h"
#include "worker/fmu/fmi2_instance.h"
#include "worker/fmu/fmi3_instance.h"
#include "worker/fmu/private_binary_copy.h"

namespace mbopt::fmu {
namespace {

// The platform folders the archive has binaries for ("binaries/<platform>/...").
std::set<std::string> ArchivePlatforms(const UnpackedArchive& archive) {
  std::set<std::string> platforms;
  const std::string prefix = "binaries/";
  for (const std::string& entry : archive.entries()) {
    if (entry.rfind(prefix, 0) != 0) continue;
    const std::size_t end = entry.find('/', prefix.size());
    if (end != std::string::npos && end > prefix.size()) platforms.insert(entry.substr(prefix.size(), end - prefix.size()));
  }
  return platforms;
}

// Errors of a load from a private copy name the FMU's own binary.
absl::Status NamingTheBinary(const absl::Status& status, const std::optional<PrivateBinaryCopy>& copy,
                             const std::filesystem::path& binary) {
  if (!copy) return status;
  return absl::Status(status.code(), absl::StrReplaceAll(status.message(), {{copy->path().string(), binary.string()}}));
}

}  // namespace

const char* ThisPlatform(int fmi_major_version) {
  const bool fmi3 = fmi_major_version >= 3;
#if defined(__linux__) && defined(__x86_64__)
  return fmi3 ? "x86_64-linux" : "linux64";
#elif defined(__linux__) && defined(__aarch64__)
  return fmi3 ? "aarch64-linux" : "linux64";
#elif defined(__linux__) && defined(__i386__)
  return fmi3 ? "x86-linux" : "linux32";
#elif defined(__linux__) && defined(__arm__)
  return fmi3 ? "aarch32-linux" : "linux32";
#else
  (void)fmi3;
  return "";
#endif
}

std::unique_ptr<ModelInstance> Fmu::Instantiate() const {
  const std::string& identifier = interface_type().model_identifier;
  if (const auto* fmi3 = std::get_if<Fmi3Library>(&library_)) {
    return Fmi3Instance::Create(fmi3->functions(), interface_, identifier, description_.guid, resource_location_);
  }
  return Fmi2Instance::Create(std::get<Fmi2Library>(library_).functions(), interface_, identifier, description_.guid,
                              resource_location_);
}

bool Fmu::exports_directional_derivative() const {
  if (const auto* fmi3 = std::get_if<Fmi3Library>(&library_)) {
    return fmi3->functions().get_directional_derivative != nullptr;
  }
  return std::get<Fmi2Library>(library_).functions().get_directional_derivative != nullptr;
}

absl::StatusOr<Fmu> Fmu::Open(const std::filesystem::path& archive_path, Interface interface,
                              const std::filesystem::path& temporary_parent) {
  auto archive = UnpackedArchive::Unpack(archive_path, temporary_parent);
  if (!archive.ok()) return archive.status();
  return Load(*std::move(archive), interface);
}

absl::StatusOr<Fmu> Fmu::OpenUnpacked(const std::filesystem::path& archive_path, const std::filesystem::path& folder,
                                      Interface interface) {
  auto archive = UnpackedArchive::Borrow(archive_path, folder);
  if (!archive.ok()) return archive.status();
  return Load(*std::move(archive), interface);
}

absl::StatusOr<Fmu> Fmu::Load(UnpackedArchive archive, Interface interface) {
  const std::filesystem::path archive_path = archive.archive_path();

  const std::filesystem::path description_path = archive.folder() / "modelDescription.xml";
  std::ifstream in(description_path, std::ios::binary);
  if (!in) {
    return absl::InvalidArgumentError(absl::StrCat(
        archive_path.string(), ": no modelDescription.xml at the archive's top level (entries: ",
        archive.entries().empty() ? "none" : absl::StrJoin(archive.entries(), ", "), ")"));
  }
  std::ostringstream text;
  text << in.rdbuf();
  const std::string label = absl::StrCat(archive_path.string(), "!modelDescription.xml");
  auto description = ParseModelDescription(text.str(), label);
  if (!description.ok()) return description.status();

  const std::optional<InterfaceType>& type =
      interface == Interface::kModelExchange ? description->model_exchange : description->co_simulation;
  if (!type.has_value()) {
    return absl::InvalidArgumentError(absl::StrCat(archive_path.string(), ": the FMU offers no ",
                                                   InterfaceName(interface), " (its model description has no <",
                                                   interface == Interface::kModelExchange ? "ModelExchange" : "CoSimulation",
                                                   "> element)"));
  }
  const int major_version = description->fmi_major_version;
  const std::string platform = ThisPlatform(major_version);
  if (platform.empty()) {
    return absl::FailedPreconditionError("this build's platform has no FMI platform name; it loads no FMU");
  }
  const std::string binary_entry = absl::StrCat("binaries/", platform, "/", type->model_identifier, ".so");
  const std::filesystem::path binary = archive.folder() / binary_entry;
  if (!std::filesystem::is_regular_file(binary)) {
    const std::set<std::string> platforms = ArchivePlatforms(archive);
    return absl::InvalidArgumentError(absl::StrCat(
        archive_path.string(), ": no binary ", binary_entry, " for this platform (", platform,
        "); the archive has binaries for: ", platforms.empty() ? "no platform" : absl::StrJoin(platforms, ", ")));
  }
  // Loaded, the copy's file can go: the process keeps its mapping.
  std::optional<PrivateBinaryCopy> private_copy;
  if (type->instantiated_once_per_process) {
    absl::StatusOr<PrivateBinaryCopy> copy = PrivateBinaryCopy::Make(binary);
    if (!copy.ok()) return copy.status();
    private_copy.emplace(*std::move(copy));
  }
  const std::filesystem::path& load_path = private_copy ? private_copy->path() : binary;
  const std::filesystem::path resources = archive.folder() / "resources";
  if (major_version >= 3) {
    auto library = Fmi3Library::Load(load_path, interface);
    if (!library.ok()) return NamingTheBinary(library.status(), private_copy, binary);
    return Fmu(std::move(archive), *std::move(description), Library(*std::move(library)), interface,
               absl::StrCat(resources.string(), "/"));
  }
  auto library = Fmi2Library::Load(load_path, interface);
  if (!library.ok()) return NamingTheBinary(library.status(), private_copy, binary);
  return Fmu(std::move(archive), *std::move(description), Library(*std::move(library)), interface,
             absl::StrCat("file://", resources.string()));
}

}  // namespace mbopt::fmu
