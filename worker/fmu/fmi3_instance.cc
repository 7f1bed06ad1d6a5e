#include "worker/fmu/fmi3_instance.h"

namespace mbopt::fmu {
namespace {

static_assert(sizeof(fmi3ValueReference) == sizeof(ValueReference));

CallStatus From(fmi3Status status) {
  switch (status) {
    case fmi3OK: return CallStatus::kOk;
    case fmi3Warning: return CallStatus::kWarning;
    case fmi3Discard: return CallStatus::kDiscard;
    case fmi3Error: return CallStatus::kError;
    case fmi3Fatal: return CallStatus::kFatal;
  }
  return CallStatus::kError;
}

const char* Fmi3StatusName(fmi3Status status) {
  switch (status) {
    case fmi3OK: return "fmi3OK";
    case fmi3Warning: return "fmi3Warning";
    case fmi3Discard: return "fmi3Discard";
    case fmi3Error: return "fmi3Error";
    case fmi3Fatal: return "fmi3Fatal";
  }
  return "an unknown fmi3Status";
}

extern "C" void LogFromFmi3(fmi3InstanceEnvironment environment, fmi3Status status, fmi3String category,
                            fmi3String message) {
  if (environment == nullptr || message == nullptr) return;
  static_cast<Fmi3Instance*>(environment)->Log(Fmi3StatusName(status), category != nullptr ? category : "", message);
}

}  // namespace

std::unique_ptr<Fmi3Instance> Fmi3Instance::Create(const Fmi3Functions& functions, Interface interface,
                                                   const std::string& model_identifier,
                                                   const std::string& instantiation_token,
                                                   const std::string& resource_path) {
  std::unique_ptr<Fmi3Instance> instance(new Fmi3Instance(&functions));
  if (interface == Interface::kModelExchange) {
    instance->instance_ = functions.instantiate_model_exchange(model_identifier.c_str(), instantiation_token.c_str(),
                                                               resource_path.c_str(), fmi3False, fmi3False,
                                                               instance.get(), LogFromFmi3);
  } else {
    instance->instance_ = functions.instantiate_co_simulation(
        model_identifier.c_str(), instantiation_token.c_str(), resource_path.c_str(), fmi3False, fmi3False,
        /*event_mode_used=*/fmi3False, /*early_return_allowed=*/fmi3False, nullptr, 0, instance.get(), LogFromFmi3,
        nullptr);
  }
  return instance;
}

Fmi3Instance::~Fmi3Instance() {
  if (instance_ != nullptr) functions_->free_instance(instance_);
}

CallStatus Fmi3Instance::SetUpExperiment(double tolerance, double start_time_s, double stop_time_s) {
  tolerance_ = tolerance;
  start_time_s_ = start_time_s;
  stop_time_s_ = stop_time_s;
  return CallStatus::kOk;
}
CallStatus Fmi3Instance::EnterInitializationMode() {
  return From(functions_->enter_initialization_mode(instance_, fmi3True, tolerance_, start_time_s_, fmi3True,
                                                    stop_time_s_));
}
CallStatus Fmi3Instance::ExitInitializationMode() { return From(functions_->exit_initialization_mode(instance_)); }
CallStatus Fmi3Instance::Terminate() { return From(functions_->terminate(instance_)); }

CallStatus Fmi3Instance::GetFloat64(const ValueReference* references, std::size_t count, double* values) {
  return From(functions_->get_float64(instance_, references, count, values, count));
}
CallStatus Fmi3Instance::SetFloat64(const ValueReference* references, std::size_t count, const double* values) {
  return From(functions_->set_float64(instance_, references, count, values, count));
}
CallStatus Fmi3Instance::GetDirectionalDerivative(const ValueReference* unknowns, std::size_t unknown_count,
                                                  const ValueReference* knowns, std::size_t known_count,
                                                  const double* seed, double* sensitivity) {
  if (functions_->get_directional_derivative == nullptr) return CallStatus::kError;
  return From(functions_->get_directional_derivative(instance_, unknowns, unknown_count, knowns, known_count, seed,
                                                     known_count, sensitivity, unknown_count));
}

CallStatus Fmi3Instance::SetTime(double time_s) { return From(functions_->set_time(instance_, time_s)); }
CallStatus Fmi3Instance::SetContinuousStates(const double* states, std::size_t count) {
  return From(functions_->set_continuous_states(instance_, states, count));
}
CallStatus Fmi3Instance::GetContinuousStates(double* states, std::size_t count) {
  return From(functions_->get_continuous_states(instance_, states, count));
}
CallStatus Fmi3Instance::GetDerivatives(double* derivatives, std::size_t count) {
  return From(functions_->get_continuous_state_derivatives(instance_, derivatives, count));
}
CallStatus Fmi3Instance::GetEventIndicators(double* indicators, std::size_t count) {
  return From(functions_->get_event_indicators(instance_, indicators, count));
}
CallStatus Fmi3Instance::EnterEventMode() { return From(functions_->enter_event_mode(instance_)); }

CallStatus Fmi3Instance::UpdateDiscreteStates(DiscreteStateUpdate* update) {
  fmi3Boolean update_needed = fmi3False;
  fmi3Boolean terminate = fmi3False;
  fmi3Boolean nominals_changed = fmi3False;
  fmi3Boolean values_changed = fmi3False;
  fmi3Boolean next_defined = fmi3False;
  fmi3Float64 next_time = 0.0;
  const CallStatus status = From(functions_->update_discrete_states(
      instance_, &update_needed, &terminate, &nominals_changed, &values_changed, &next_defined, &next_time));
  update->update_needed = update_needed;
  update->terminate = terminate;
  update->continuous_states_changed = values_changed;
  update->next_event_time_defined = next_defined;
  update->next_event_time_s = next_time;
  return status;
}

CallStatus Fmi3Instance::EnterContinuousTimeMode() { return From(functions_->enter_continuous_time_mode(instance_)); }

CallStatus Fmi3Instance::CompletedIntegratorStep(bool* enter_event_mode, bool* terminate) {
  fmi3Boolean event = fmi3False;
  fmi3Boolean stop = fmi3False;
  const CallStatus status = From(functions_->completed_integrator_step(instance_, fmi3True, &event, &stop));
  *enter_event_mode = event;
  *terminate = stop;
  return status;
}

CallStatus Fmi3Instance::DoStep(double time_s, double step_s, bool* terminate) {
  // Without event mode and early return, the FMU steps the whole interval;
  // eventHandlingNeeded and earlyReturn stay false.
  fmi3Boolean event_handling_needed = fmi3False;
  fmi3Boolean stop = fmi3False;
  fmi3Boolean early_return = fmi3False;
  fmi3Float64 last_successful_time_s = time_s;
  const CallStatus status = From(functions_->do_step(instance_, time_s, step_s, fmi3True, &event_handling_needed,
                                                     &stop, &early_return, &last_successful_time_s));
  *terminate = stop;
  return status;
}

const char* Fmi3Instance::FunctionName(Call call) const {
  switch (call) {
    case Call::kSetUpExperiment:
    case Call::kEnterInitializationMode: return "fmi3EnterInitializationMode";
    case Call::kExitInitializationMode: return "fmi3ExitInitializationMode";
    case Call::kSetFloat64: return "fmi3SetFloat64";
    case Call::kGetFloat64: return "fmi3GetFloat64";
    case Call::kSetTime: return "fmi3SetTime";
    case Call::kSetContinuousStates: return "fmi3SetContinuousStates";
    case Call::kGetContinuousStates: return "fmi3GetContinuousStates";
    case Call::kGetDerivatives: return "fmi3GetContinuousStateDerivatives";
    case Call::kGetEventIndicators: return "fmi3GetEventIndicators";
    case Call::kEnterEventMode: return "fmi3EnterEventMode";
    case Call::kUpdateDiscreteStates: return "fmi3UpdateDiscreteStates";
    case Call::kEnterContinuousTimeMode: return "fmi3EnterContinuousTimeMode";
    case Call::kCompletedIntegratorStep: return "fmi3CompletedIntegratorStep";
    case Call::kDoStep: return "fmi3DoStep";
    case Call::kGetDirectionalDerivative: return "fmi3GetDirectionalDerivative";
  }
  return "an fmi3 function";
}

const char* Fmi3Instance::StatusName(CallStatus status) const {
  switch (status) {
    case CallStatus::kOk: return "fmi3OK";
    case CallStatus::kWarning: return "fmi3Warning";
    case CallStatus::kDiscard: return "fmi3Discard";
    case CallStatus::kError: return "fmi3Error";
    case CallStatus::kFatal: return "fmi3Fatal";
  }
  return "an unknown fmi3Status";
}

}  // namespace mbopt::fmu
