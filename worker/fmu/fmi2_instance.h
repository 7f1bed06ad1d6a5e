// One instance of an FMI 2.0 FMU's model (fmi2Instantiate ..
// fmi2FreeInstance) behind the version-independent ModelInstance, with the
// logger that keeps the FMU's recent messages for failure reasons.
#pragma once

#include <memory>
#include <string>

#include "worker/fmu/fmi2_api.h"
#include "worker/fmu/fmi2_library.h"
#include "worker/fmu/model_instance.h"

namespace mbopt::fmu {

class Fmi2Instance final : public ModelInstance {
 public:
  // Instantiates the model; instantiated() is false when the FMU refused.
  // Held by pointer: the FMU keeps the instance's address for its logger.
  static std::unique_ptr<Fmi2Instance> Create(const Fmi2Functions& functions, Interface interface,
                                              const std::string& model_identifier, const std::string& guid,
                                              const std::string& resource_uri);
  ~Fmi2Instance() override;

  bool instantiated() const override { return component_ != nullptr; }
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
  explicit Fmi2Instance(const Fmi2Functions* functions) : functions_(functions) {}

  const Fmi2Functions* functions_;
  fmi2CallbackFunctions callbacks_{};
  fmi2Component component_ = nullptr;
};

}  // namespace mbopt::fmu
