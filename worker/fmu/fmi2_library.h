// An FMU's shared library loaded with dlopen, with the FMI 2.0 functions of
// one interface type resolved. The library is closed when the object goes.
#pragma once

#include <filesystem>

#include "absl/status/statusor.h"
#include "worker/fmu/binary_symbols.h"
#include "worker/fmu/fmi2_api.h"
#include "worker/fmu/model_instance.h"

namespace mbopt::fmu {

struct Fmi2Functions {
  fmi2GetVersionTYPE* get_version = nullptr;
  fmi2InstantiateTYPE* instantiate = nullptr;
  fmi2FreeInstanceTYPE* free_instance = nullptr;
  fmi2SetupExperimentTYPE* setup_experiment = nullptr;
  fmi2EnterInitializationModeTYPE* enter_initialization_mode = nullptr;
  fmi2ExitInitializationModeTYPE* exit_initialization_mode = nullptr;
  fmi2TerminateTYPE* terminate = nullptr;
  fmi2GetRealTYPE* get_real = nullptr;
  fmi2SetRealTYPE* set_real = nullptr;
  fmi2GetDirectionalDerivativeTYPE* get_directional_derivative = nullptr;  // may stay null
  // Model Exchange.
  fmi2EnterEventModeTYPE* enter_event_mode = nullptr;
  fmi2NewDiscreteStatesTYPE* new_discrete_states = nullptr;
  fmi2EnterContinuousTimeModeTYPE* enter_continuous_time_mode = nullptr;
  fmi2CompletedIntegratorStepTYPE* completed_integrator_step = nullptr;
  fmi2SetTimeTYPE* set_time = nullptr;
  fmi2SetContinuousStatesTYPE* set_continuous_states = nullptr;
  fmi2GetDerivativesTYPE* get_derivatives = nullptr;
  fmi2GetEventIndicatorsTYPE* get_event_indicators = nullptr;
  fmi2GetContinuousStatesTYPE* get_continuous_states = nullptr;
  // Co-Simulation.
  fmi2DoStepTYPE* do_step = nullptr;
};

class Fmi2Library {
 public:
  // Loads `binary` and resolves the functions `interface` needs; an error
  // names the binary and the first missing function, or dlopen's reason.
  static absl::StatusOr<Fmi2Library> Load(const std::filesystem::path& binary, Interface interface);

  Fmi2Library(Fmi2Library&&) noexcept = default;
  Fmi2Library& operator=(Fmi2Library&&) noexcept = default;

  const Fmi2Functions& functions() const { return functions_; }

 private:
  Fmi2Library() = default;

  OpenedBinary binary_;
  Fmi2Functions functions_;
};

}  // namespace mbopt::fmu
