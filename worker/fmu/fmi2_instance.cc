#include "worker/fmu/fmi2_instance.h"

#include <cstdarg>
#include <cstdio>
#include <cstdlib>

namespace mbopt::fmu {
namespace {

static_assert(sizeof(fmi2ValueReference) == sizeof(ValueReference));

CallStatus From(fmi2Status status) {
  switch (status) {
    case fmi2OK: return CallStatus::kOk;
    case fmi2Warning: return CallStatus::kWarning;
    case fmi2Discard: return CallStatus::kDiscard;
    case fmi2Error: return CallStatus::kError;
    case fmi2Fatal: return CallStatus::kFatal;
    case fmi2Pending: return CallStatus::kError;
  }
  return CallStatus::kError;
}

const char* Fmi2StatusName(fmi2Status status) {
  switch (status) {
    case fmi2OK: return "fmi2OK";
    case fmi2Warning: return "fmi2Warning";
    case fmi2Discard: return "fmi2Discard";
    case fmi2Error: return "fmi2Error";
    case fmi2Fatal: return "fmi2Fatal";
    case fmi2Pending: return "fmi2Pending";
  }
  return "an unknown fmi2Status";
}

extern "C" void LogFromFmi2(fmi2ComponentEnvironment environment, fmi2String /*instance_name*/, fmi2Status status,
                            fmi2String category, fmi2String message, ...) {
  if (environment == nullptr || message == nullptr) return;
  char text[1024];
  va_list arguments;
  va_start(arguments, message);
  std::vsnprintf(text, sizeof text, message, arguments);
  va_end(arguments);
  static_cast<Fmi2Instance*>(environment)->Log(Fmi2StatusName(status), category != nullptr ? category : "", text);
}

extern "C" void* AllocateForFmi2(size_t count, size_t size) { return std::calloc(count, size); }
extern "C" void FreeForFmi2(void* object) { std::free(object); }

}  // namespace

std::unique_ptr<Fmi2Instance> Fmi2Instance::Create(const Fmi2Functions& functions, Interface interface,
                                                   const std::string& model_identifier, const std::string& guid,
                                                   const std::string& resource_uri) {
  std::unique_ptr<Fmi2Instance> instance(new Fmi2Instance(&functions));
  instance->callbacks_.logger = LogFromFmi2;
  instance->callbacks_.allocateMemory = AllocateForFmi2;
  instance->callbacks_.freeMemory = FreeForFmi2;
  instance->callbacks_.stepFinished = nullptr;
  instance->callbacks_.componentEnvironment = instance.get();
  const fmi2Type type = interface == Interface::kModelExchange ? fmi2ModelExchange : fmi2CoSimulation;
  instance->component_ = functions.instantiate(model_identifier.c_str(), type, guid.c_str(), resource_uri.c_str(),
                                               &instance->callbacks_, fmi2False, fmi2False);
  return instance;
}

Fmi2Instance::~Fmi2Instance() {
  if (component_ != nullptr) functions_->free_instance(component_);
}

CallStatus Fmi2Instance::SetUpExperiment(double tolerance, double start_time_s, double stop_time_s) {
  return From(functions_->setup_experiment(component_, fmi2True, tolerance, start_time_s, fmi2True, stop_time_s));
}
CallStatus Fmi2Instance::EnterInitializationMode() { return From(functions_->enter_initialization_mode(component_)); }
CallStatus Fmi2Instance::ExitInitializationMode() { return From(functions_->exit_initialization_mode(component_)); }
CallStatus Fmi2Instance::Terminate() { return From(functions_->terminate(component_)); }

CallStatus Fmi2Instance::GetFloat64(const ValueReference* references, std::size_t count, double* values) {
  return From(functions_->get_real(component_, references, count, values));
}
CallStatus Fmi2Instance::SetFloat64(const ValueReference* references, std::size_t count, const double* values) {
  return From(functions_->set_real(component_, references, count, values));
}
CallStatus Fmi2Instance::GetDirectionalDerivative(const ValueReference* unknowns, std::size_t unknown_count,
                                                  const ValueReference* knowns, std::size_t known_count,
                                                  const double* seed, double* sensitivity) {
  if (functions_->get_directional_derivative == nullptr) return CallStatus::kError;
  return From(functions_->get_directional_derivative(component_, unknowns, unknown_count, knowns, known_count, seed,
                                                     sensitivity));
}

CallStatus Fmi2Instance::SetTime(double time_s) { return From(functions_->set_time(component_, time_s)); }
CallStatus Fmi2Instance::SetContinuousStates(const double* states, std::size_t count) {
  return From(functions_->set_continuous_states(component_, states, count));
}
CallStatus Fmi2Instance::GetContinuousStates(double* states, std::size_t count) {
  return From(functions_->get_continuous_states(component_, states, count));
}
CallStatus Fmi2Instance::GetDerivatives(double* derivatives, std::size_t count) {
  return From(functions_->get_derivatives(component_, derivatives, count));
}
CallStatus Fmi2Instance::GetEventIndicators(double* indicators, std::size_t count) {
  return From(functions_->get_event_indicators(component_, indicators, count));
}
CallStatus Fmi2Instance::EnterEventMode() { return From(functions_->enter_event_mode(component_)); }

CallStatus Fmi2Instance::UpdateDiscreteStates(DiscreteStateUpdate* update) {
  fmi2EventInfo info{};
  const CallStatus status = From(functions_->new_discrete_states(component_, &info));
  update->update_needed = info.newDiscreteStatesNeeded == fmi2True;
  update->terminate = info.terminateSimulation == fmi2True;
  update->continuous_states_changed = info.valuesOfContinuousStatesChanged == fmi2True;
  update->next_event_time_defined = info.nextEventTimeDefined == fmi2True;
  update->next_event_time_s = info.nextEventTime;
  return status;
}

CallStatus Fmi2Instance::EnterContinuousTimeMode() { return From(functions_->enter_continuous_time_mode(component_)); }

CallStatus Fmi2Instance::CompletedIntegratorStep(bool* enter_event_mode, bool* terminate) {
  fmi2Boolean event = fmi2False;
  fmi2Boolean stop = fmi2False;
  const CallStatus status = From(functions_->completed_integrator_step(component_, fmi2True, &event, &stop));
  *enter_event_mode = event == fmi2True;
  *terminate = stop == fmi2True;
  return status;
}

CallStatus Fmi2Instance::DoStep(double time_s, double step_s, bool* terminate) {
  // FMI 2.0 has no flag for it: an FMU that wants to stop answers fmi2Discard.
  *terminate = false;
  return From(functions_->do_step(component_, time_s, step_s, fmi2True));
}

const char* Fmi2Instance::FunctionName(Call call) const {
  switch (call) {
    case Call::kSetUpExperiment: return "fmi2SetupExperiment";
    case Call::kEnterInitializationMode: return "fmi2EnterInitializationMode";
    case Call::kExitInitializationMode: return "fmi2ExitInitializationMode";
    case Call::kSetFloat64: return "fmi2SetReal";
    case Call::kGetFloat64: return "fmi2GetReal";
    case Call::kSetTime: return "fmi2SetTime";
    case Call::kSetContinuousStates: return "fmi2SetContinuousStates";
    case Call::kGetContinuousStates: return "fmi2GetContinuousStates";
    case Call::kGetDerivatives: return "fmi2GetDerivatives";
    case Call::kGetEventIndicators: return "fmi2GetEventIndicators";
    case Call::kEnterEventMode: return "fmi2EnterEventMode";
    case Call::kUpdateDiscreteStates: return "fmi2NewDiscreteStates";
    case Call::kEnterContinuousTimeMode: return "fmi2EnterContinuousTimeMode";
    case Call::kCompletedIntegratorStep: return "fmi2CompletedIntegratorStep";
    case Call::kDoStep: return "fmi2DoStep";
    case Call::kGetDirectionalDerivative: return "fmi2GetDirectionalDerivative";
  }
  return "an fmi2 function";
}

const char* Fmi2Instance::StatusName(CallStatus status) const {
  switch (status) {
    case CallStatus::kOk: return "fmi2OK";
    case CallStatus::kWarning: return "fmi2Warning";
    case CallStatus::kDiscard: return "fmi2Discard";
    case CallStatus::kError: return "fmi2Error";
    case CallStatus::kFatal: return "fmi2Fatal";
  }
  return "an unknown fmi2Status";
}

}  // namespace mbopt::fmu
