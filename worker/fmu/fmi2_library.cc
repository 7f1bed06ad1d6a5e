#include "worker/fmu/fmi2_library.h"

#include <dlfcn.h>

#include <string>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace mbopt::fmu {
namespace {

template <typename Function>
absl::Status Resolve(void* handle, const std::filesystem::path& binary, const char* name, Function** out,
                     bool required = true) {
  dlerror();
  void* symbol = dlsym(handle, name);
  if (symbol == nullptr && required) {
    return absl::InvalidArgumentError(
        absl::StrCat(binary.string(), ": the FMU's binary has no function ", name));
  }
  *out = reinterpret_cast<Function*>(symbol);
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<Fmi2Library> Fmi2Library::Load(const std::filesystem::path& binary, Interface interface) {
  Fmi2Library library;
  // RTLD_LOCAL: two FMUs exporting the same fmi2 names do not see each other.
  library.handle_ = dlopen(binary.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (library.handle_ == nullptr) {
    const char* reason = dlerror();
    return absl::InvalidArgumentError(
        absl::StrCat(binary.string(), ": the FMU's binary cannot be loaded: ", reason ? reason : "unknown"));
  }
  Fmi2Functions& f = library.functions_;
  const bool me = interface == Interface::kModelExchange;
  const absl::Status statuses[] = {
      Resolve(library.handle_, binary, "fmi2GetVersion", &f.get_version),
      Resolve(library.handle_, binary, "fmi2Instantiate", &f.instantiate),
      Resolve(library.handle_, binary, "fmi2FreeInstance", &f.free_instance),
      Resolve(library.handle_, binary, "fmi2SetupExperiment", &f.setup_experiment),
      Resolve(library.handle_, binary, "fmi2EnterInitializationMode", &f.enter_initialization_mode),
      Resolve(library.handle_, binary, "fmi2ExitInitializationMode", &f.exit_initialization_mode),
      Resolve(library.handle_, binary, "fmi2Terminate", &f.terminate),
      Resolve(library.handle_, binary, "fmi2GetReal", &f.get_real),
      Resolve(library.handle_, binary, "fmi2SetReal", &f.set_real),
      Resolve(library.handle_, binary, "fmi2GetDirectionalDerivative", &f.get_directional_derivative, false),
      Resolve(library.handle_, binary, "fmi2EnterEventMode", &f.enter_event_mode, me),
      Resolve(library.handle_, binary, "fmi2NewDiscreteStates", &f.new_discrete_states, me),
      Resolve(library.handle_, binary, "fmi2EnterContinuousTimeMode", &f.enter_continuous_time_mode, me),
      Resolve(library.handle_, binary, "fmi2CompletedIntegratorStep", &f.completed_integrator_step, me),
      Resolve(library.handle_, binary, "fmi2SetTime", &f.set_time, me),
      Resolve(library.handle_, binary, "fmi2SetContinuousStates", &f.set_continuous_states, me),
      Resolve(library.handle_, binary, "fmi2GetDerivatives", &f.get_derivatives, me),
      Resolve(library.handle_, binary, "fmi2GetEventIndicators", &f.get_event_indicators, me),
      Resolve(library.handle_, binary, "fmi2GetContinuousStates", &f.get_continuous_states, me),
      Resolve(library.handle_, binary, "fmi2DoStep", &f.do_step, !me),
  };
  for (const absl::Status& status : statuses) {
    if (!status.ok()) return status;
  }
  const std::string version = f.get_version();
  if (version != "2.0") {
    return absl::InvalidArgumentError(
        absl::StrCat(binary.string(), ": fmi2GetVersion says \"", version, "\", expected \"2.0\""));
  }
  return library;
}

Fmi2Library& Fmi2Library::operator=(Fmi2Library&& other) noexcept {
  if (this != &other) {
    if (handle_ != nullptr) dlclose(handle_);
    handle_ = other.handle_;
    functions_ = other.functions_;
    other.handle_ = nullptr;
  }
  return *this;
}

Fmi2Library::~Fmi2Library() {
  if (handle_ != nullptr) dlclose(handle_);
}

}  // namespace mbopt::fmu
