#include "worker/fmu/fmi3_library.h"

#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "worker/fmu/binary_symbols.h"

namespace mbopt::fmu {

absl::StatusOr<Fmi3Library> Fmi3Library::Load(const std::filesystem::path& binary, Interface interface) {
  Fmi3Library library;
  absl::StatusOr<OpenedBinary> opened = OpenBinary(binary);
  if (!opened.ok()) return opened.status();
  library.binary_ = *std::move(opened);
  Fmi3Functions& f = library.functions_;
  void* h = library.binary_.handle();
  const bool me = interface == Interface::kModelExchange;
  const absl::Status statuses[] = {
      ResolveFunction(h, binary, "fmi3GetVersion", &f.get_version),
      ResolveFunction(h, binary, "fmi3InstantiateModelExchange", &f.instantiate_model_exchange, me),
      ResolveFunction(h, binary, "fmi3InstantiateCoSimulation", &f.instantiate_co_simulation, !me),
      ResolveFunction(h, binary, "fmi3FreeInstance", &f.free_instance),
      ResolveFunction(h, binary, "fmi3EnterInitializationMode", &f.enter_initialization_mode),
      ResolveFunction(h, binary, "fmi3ExitInitializationMode", &f.exit_initialization_mode),
      ResolveFunction(h, binary, "fmi3Terminate", &f.terminate),
      ResolveFunction(h, binary, "fmi3GetFloat64", &f.get_float64),
      ResolveFunction(h, binary, "fmi3SetFloat64", &f.set_float64),
      ResolveFunction(h, binary, "fmi3GetDirectionalDerivative", &f.get_directional_derivative, false),
      ResolveFunction(h, binary, "fmi3EnterEventMode", &f.enter_event_mode, me),
      ResolveFunction(h, binary, "fmi3UpdateDiscreteStates", &f.update_discrete_states, me),
      ResolveFunction(h, binary, "fmi3EnterContinuousTimeMode", &f.enter_continuous_time_mode, me),
      ResolveFunction(h, binary, "fmi3CompletedIntegratorStep", &f.completed_integrator_step, me),
      ResolveFunction(h, binary, "fmi3SetTime", &f.set_time, me),
      ResolveFunction(h, binary, "fmi3SetContinuousStates", &f.set_continuous_states, me),
      ResolveFunction(h, binary, "fmi3GetContinuousStateDerivatives", &f.get_continuous_state_derivatives, me),
      ResolveFunction(h, binary, "fmi3GetEventIndicators", &f.get_event_indicators, me),
      ResolveFunction(h, binary, "fmi3GetContinuousStates", &f.get_continuous_states, me),
      ResolveFunction(h, binary, "fmi3DoStep", &f.do_step, !me),
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

}  // namespace mbopt::fmu
