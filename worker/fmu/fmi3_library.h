// An FMI 3.0 FMU's shared library loaded with dlopen, with the functions of
// one interface type resolved. The library is closed when the object goes.
#pragma once

#include <filesystem>

#include "absl/status/statusor.h"
#include "worker/fmu/binary_symbols.h"
#include "worker/fmu/fmi3_api.h"
#include "worker/fmu/model_instance.h"

namespace mbopt::fmu {

struct Fmi3Functions {
  fmi3GetVersionTYPE* get_version = nullptr;
  fmi3InstantiateModelExchangeTYPE* instantiate_model_exchange = nullptr;  // Model Exchange only
  fmi3InstantiateCoSimulationTYPE* instantiate_co_simulation = nullptr;    // Co-Simulation only
  fmi3FreeInstanceTYPE* free_instance = nullptr;
  fmi3EnterInitializationModeTYPE* enter_initialization_mode = nullptr;
  fmi3ExitInitializationModeTYPE* exit_initialization_mode = nullptr;
  fmi3TerminateTYPE* terminate = nullptr;
  fmi3GetFloat64TYPE* get_float64 = nullptr;
  fmi3SetFloat64TYPE* set_float64 = nullptr;
  fmi3GetDirectionalDerivativeTYPE* get_directional_derivative = nullptr;  // may stay null
  // Model Exchange.
  fmi3EnterEventModeTYPE* enter_event_mode = nullptr;
  fmi3UpdateDiscreteStatesTYPE* update_discrete_states = nullptr;
  fmi3EnterContinuousTimeModeTYPE* enter_continuous_time_mode = nullptr;
  fmi3CompletedIntegratorStepTYPE* completed_integrator_step = nullptr;
  fmi3SetTimeTYPE* set_time = nullptr;
  fmi3SetContinuousStatesTYPE* set_continuous_states = nullptr;
  fmi3GetContinuousStateDerivativesTYPE* get_continuous_state_derivatives = nullptr;
  fmi3GetEventIndicatorsTYPE* get_event_indicators = nullptr;
  fmi3GetContinuousStatesTYPE* get_continuous_states = nullptr;
  // Co-Simulation.
  fmi3DoStepTYPE* do_step = nullptr;
};

class Fmi3Library {
 public:
  // Loads `binary` and resolves the functions `interface` needs; an error
  // names the binary and the first missing function, or dlopen's reason.
  static absl::StatusOr<Fmi3Library> Load(const std::filesystem::path& binary, Interface interface);

  Fmi3Library(Fmi3Library&&) noexcept = default;
  Fmi3Library& operator=(Fmi3Library&&) noexcept = default;

  const Fmi3Functions& functions() const { return functions_; }

 private:
  Fmi3Library() = default;

  OpenedBinary binary_;
  Fmi3Functions functions_;
};

}  // namespace mbopt::fmu
