#include "worker/fmu/fmi3_library.h"

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

absl::StatusOr<Fmi3Library> Fmi3Library::Load(const std::filesystem::path& binary, Interface interface) {
  Fmi3Library library;
  // RTLD_LOCAL: two FMUs exporting the same fmi3 names do not see each other.
  library.handle_ = dlopen(binary.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (library.handle_ == nullptr) {
    const char* reason = dlerror();
    return absl::InvalidArgumentError(
        absl::StrCat(binary.string(), ": the FMU's binary cannot be loaded: ", reason ? reason : "unknown"));
  }
  Fmi3Functions& f = library.functions_;
  void* h = library.handle_;
  const bool me = interface == Interface::kModelExchange;
  const absl::Status statuses[] = {
      Resolve(h, binary, "fmi3GetVersion", &f.get_version),
      Resolve(h, binary, "fmi3InstantiateModelExchange", &f.instantiate_model_exchange, me),
      Resolve(h, binary, "fmi3InstantiateCoSimulation", &f.instantiate_co_simulation, !me),
      Resolve(h, binary, "fmi3FreeInstance", &f.free_instance),
      Resolve(h, binary, "fmi3EnterInitializationMode", &f.enter_initialization_mode),
      Resolve(h, binary, "fmi3ExitInitializationMode", &f.exit_initialization_mode),
      Resolve(h, binary, "fmi3Terminate", &f.terminate),
      Resolve(h, binary, "fmi3GetFloat64", &f.get_float64),
      Resolve(h, binary, "fmi3SetFloat64", &f.set_float64),
      Resolve(h, binary, "fmi3GetDirectionalDerivative", &f.get_directional_derivative, false),
      Resolve(h, binary, "fmi3EnterEventMode", &f.enter_event_mode, me),
      Resolve(h, binary, "fmi3UpdateDiscreteStates", &f.update_discrete_states, me),
      Resolve(h, binary, "fmi3EnterContinuousTimeMode", &f.enter_continuous_time_mode, me),
      Resolve(h, binary, "fmi3CompletedIntegratorStep", &f.completed_integrator_step, me),
      Resolve(h, binary, "fmi3SetTime", &f.set_time, me),
      Resolve(h, binary, "fmi3SetContinuousStates", &f.set_continuous_states, me),
      Resolve(h, binary, "fmi3GetContinuousStateDerivatives", &f.get_continuous_state_derivatives, me),
      Resolve(h, binary, "fmi3GetEventIndicators", &f.get_event_indicators, me),
      Resolve(h, binary, "fmi3GetContinuousStates", &f.get_continuous_states, me),
      Resolve(h, binary, "fmi3DoStep", &f.do_step, !me),
  };
  for (const absl::Status& status : statuses) {
    if (!status.ok()) return status;
  }
  // Minor versions (3.0.1, 3.0.2) are compatible with the 3.0 interface.
  const std::string version = f.get_version();
  if (version.rfind("3.", 0) != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(binary.string(), ": fmi3GetVersion says \"", version, "\", expected \"3.0\""));
  }
  return library;
}

Fmi3Library& Fmi3Library::operator=(Fmi3Library&& other) noexcept {
  if (this != &other) {
    if (handle_ != nullptr) dlclose(handle_);
    handle_ = other.handle_;
    functions_ = other.functions_;
    other.handle_ = nullptr;
  }
  return *this;
}

Fmi3Library::~Fmi3Library() {
  if (handle_ != nullptr) dlclose(handle_);
}

}  // namespace mbopt::fmu
