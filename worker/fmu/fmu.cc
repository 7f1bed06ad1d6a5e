#include "worker/fmu/fmu.h"

#include <fstream>
#include <set>
#include <sstream>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

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

}  // namespace

const char* ThisPlatform() {
#if defined(__linux__) && (defined(__x86_64__) || defined(__aarch64__))
  return "linux64";
#elif defined(__linux__) && (defined(__i386__) || defined(__arm__))
  return "linux32";
#else
  return "";
#endif
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
  const std::string platform = ThisPlatform();
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
  auto library = Fmi2Library::Load(binary, interface);
  if (!library.ok()) return library.status();

  const std::string resource_uri = absl::StrCat("file://", (archive.folder() / "resources").string());
  return Fmu(std::move(archive), *std::move(description), *std::move(library), interface, resource_uri);
}

}  // namespace mbopt::fmu
