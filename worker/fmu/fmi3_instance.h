// One instance of an FMI 3.0 FMU's model (fmi3InstantiateModelExchange or
// fmi3InstantiateCoSimulation .. fmi3FreeInstance) behind the
// version-independent ModelInstance. Co-simulation instances are made
// without event mode and without early return: mbopt steps them at fixed
// communication points only.
#pragma once

#include <memory>
#include <string>

#include "worker/fmu/fmi3_api.h"
#include "worker/fmu/fmi3_library.h"
#include "worker/fmu/model_instance.h"

namespace mbopt::fmu {

class Fmi3Instance final : public ModelInstance {
 public:
  // Instantiates the model; instantiated() is false when the FMU refused.
  // `resource_path` is the unpacked resources folder, ending in '/'.
  static std::unique_ptr<Fmi3Instance> Create(const Fmi3Functions& functions, Interface interface,
                                              const std::string& model_identifier,
                                              const std::string& instantiation_token,
                                              const std::string& resource_path);
  ~Fmi3Instance() override;

  bool instantiated() const override { return instance_ != nullptr; }
  CallStatus SetUpExperiment(double tolerance, double start_time_s, double stop_time_s) override;
  CallStatus EnterInitializationMode() override;
  CallStatus ExitInitializationMode() override;
  CallStatus Terminate() override;
  CallStatus GetFloat64(const ValueReference* references, std::size_t count, double* values) override;
  CallStatus SetFloat64(const ValueReference* references, std::size_t count, const double* values) override;
  CallStatus GetDirectionalDerivative(const ValueReference* unknowns, std::size_t unknown_count,
                                      const ValueReference* knowns, std::size_t known_count, const double* seed,
                                      double* sensitivity) override;
  CallStatus SetTime(double time_s) override;
  CallStatus SetContinuousStates(const double* states, std::size_t count) override;
  CallStatus GetContinuousStates(double* states, std::size_t count) override;
  CallStatus GetDerivatives(double* derivatives, std::size_t count) override;
  CallStatus GetEventIndicators(double* indicators, std::size_t count) override;
  CallStatus EnterEventMode() override;
  CallStatus UpdateDiscreteStates(DiscreteStateUpdate* update) override;
  CallStatus EnterContinuousTimeMode() override;
  CallStatus CompletedIntegratorStep(bool* enter_event_mode, bool* terminate) override;
  CallStatus DoStep(double time_s, double step_s, bool* terminate) override;
  const char* FunctionName(Call call) const override;
  const char* StatusName(CallStatus status) const override;

 private:
  explicit Fmi3Instance(const Fmi3Functions* functions) : functions_(functions) {}

  const Fmi3Functions* functions_;
  fmi3Instance instance_ = nullptr;
  // FMI 3.0 takes the experiment on entering initialization mode.
  double tolerance_ = 0.0;
  double start_time_s_ = 0.0;
  double stop_time_s_ = 0.0;
};

}  // namespace mbopt::fmu
