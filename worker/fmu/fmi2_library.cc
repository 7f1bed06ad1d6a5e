#include "worker/fmu/fmi2_library.h"

#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "worker/fmu/binary_symbols.h"

namespace mbopt::fmu {

absl::StatusOr<Fmi2Library> Fmi2Library::Load(const std::filesystem::path& binary, Interface interface) {
  Fmi2Library library;
  absl::StatusOr<OpenedBinary> opened = OpenBinary(binary);
  if (!opened.ok()) return opened.status();
  library.binary_ = *std::move(opened);
  Fmi2Functions& f = library.functions_;
  void* h = library.binary_.handle();
  const bool me = interface == Interface::kModelExchange;
  const absl::Status statuses[] = {
      ResolveFunction(h, binary, "fmi2GetVersion", &f.get_version),
      ResolveFunction(h, binary, "fmi2Instantiate", &f.instantiate),
      ResolveFunction(h, binary, "fmi2FreeInstance", &f.free_instance),
      ResolveFunction(h, binary, "fmi2SetupExperiment", &f.setup_experiment),
      ResolveFunction(h, binary, "fmi2EnterInitializationMode", &f.enter_initialization_mode),
      ResolveFunction(h, binary, "fmi2ExitInitializationMode", &f.exit_initialization_mode),
      ResolveFunction(h, binary, "fmi2Terminate", &f.terminate),
      ResolveFunction(h, binary, "fmi2GetReal", &f.get_real),
      ResolveFunction(h, binary, "fmi2SetReal", &f.set_real),
      ResolveFunction(h, binary, "fmi2GetDirectionalDerivative", &f.get_directional_derivative, false),
      ResolveFunction(h, binary, "fmi2EnterEventMode", &f.enter_event_mode, me),
      ResolveFunction(h, binary, "fmi2NewDiscreteStates", &f.new_discrete_states, me),
      ResolveFunction(h, binary, "fmi2EnterContinuousTimeMode", &f.enter_continuous_time_mode, me),
      ResolveFunction(h, binary, "fmi2CompletedIntegratorStep", &f.completed_integrator_step, me),
      ResolveFunction(h, binary, "fmi2SetTime", &f.set_time, me),
      ResolveFunction(h, binary, "fmi2SetContinuousStates", &f.set_continuous_states, me),
      ResolveFunction(h, binary, "fmi2GetDerivatives", &f.get_derivatives, me),
      ResolveFunction(h, binary, "fmi2GetEventIndicators", &f.get_event_indicators, me),
      ResolveFunction(h, binary, "fmi2GetContinuousStates", &f.get_continuous_states, me),
      ResolveFunction(h, binary, "fmi2DoStep", &f.do_step, !me),
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

}  // namespace mbopt::fmu
