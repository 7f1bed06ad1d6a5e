// One instance of an FMU's model, whichever FMI version the FMU speaks: the
// calls the simulation loops make (simulation.cc, model_exchange.cc), so
// that one driver integrates and steps FMI 2.0 and FMI 3.0 FMUs alike.
// Fmi2Instance and Fmi3Instance translate them into their version's calls.
//
// Every call answers with the FMU's status; a failed call is turned into a
// reason by Failure(), which names the FMU's own function and status
// ("fmi3DoStep returned fmi3Error at t = 0.3 s (FMU: ...)") and carries the
// FMU's last log messages.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <string_view>

namespace mbopt::fmu {

using ValueReference = std::uint32_t;

enum class Interface { kModelExchange, kCoSimulation };

const char* InterfaceName(Interface interface);

// FMI's statuses, in the standard's order of severity (fmi2Pending, of
// asynchronous co-simulation that mbopt never asks for, reads as kError).
enum class CallStatus { kOk, kWarning, kDiscard, kError, kFatal };

inline bool Succeeded(CallStatus status) { return status <= CallStatus::kWarning; }

// The calls, for naming them in failures in the FMU's version.
enum class Call {
  kSetUpExperiment,
  kEnterInitializationMode,
  kExitInitializationMode,
  kSetFloat64,
  kGetFloat64,
  kSetTime,
  kSetContinuousStates,
  kGetContinuousStates,
  kGetDerivatives,
  kGetEventIndicators,
  kEnterEventMode,
  kUpdateDiscreteStates,
  kEnterContinuousTimeMode,
  kCompletedIntegratorStep,
  kDoStep,
  kGetDirectionalDerivative,
};

// What the FMU says after its discrete states were updated at an event.
struct DiscreteStateUpdate {
  bool update_needed = false;  // call again before leaving event mode
  bool terminate = false;
  bool continuous_states_changed = false;
  bool next_event_time_defined = false;
  double next_event_time_s = 0.0;
};

class ModelInstance {
 public:
  ModelInstance() = default;
  ModelInstance(const ModelInstance&) = delete;
  ModelInstance& operator=(const ModelInstance&) = delete;
  virtual ~ModelInstance() = default;

  // False when the FMU refused to make the instance (RecentMessages() says
  // why if it logged anything); no other call may be made then.
  virtual bool instantiated() const = 0;

  // The run's tolerance and time span; before the parameters are set and
  // initialization mode is entered (FMI 3.0 passes them on entering it).
  virtual CallStatus SetUpExperiment(double tolerance, double start_time_s, double stop_time_s) = 0;
  virtual CallStatus EnterInitializationMode() = 0;
  // Afterwards a Model Exchange FMU is in event mode, a co-simulation FMU
  // ready to step.
  virtual CallStatus ExitInitializationMode() = 0;
  virtual CallStatus Terminate() = 0;

  virtual CallStatus GetFloat64(const ValueReference* references, std::size_t count, double* values) = 0;
  virtual CallStatus SetFloat64(const ValueReference* references, std::size_t count, const double* values) = 0;
  // sensitivity[i] = sum over j of d unknown_i / d known_j * seed[j], at
  // the instance's current time, states and parameters.
  virtual CallStatus GetDirectionalDerivative(const ValueReference* unknowns, std::size_t unknown_count,
                                              const ValueReference* knowns, std::size_t known_count,
                                              const double* seed, double* sensitivity) = 0;

  // Model Exchange.
  virtual CallStatus SetTime(double time_s) = 0;
  virtual CallStatus SetContinuousStates(const double* states, std::size_t count) = 0;
  virtual CallStatus GetContinuousStates(double* states, std::size_t count) = 0;
  virtual CallStatus GetDerivatives(double* derivatives, std::size_t count) = 0;
  virtual CallStatus GetEventIndicators(double* indicators, std::size_t count) = 0;
  virtual CallStatus EnterEventMode() = 0;
  virtual CallStatus UpdateDiscreteStates(DiscreteStateUpdate* update) = 0;
  virtual CallStatus EnterContinuousTimeMode() = 0;
  virtual CallStatus CompletedIntegratorStep(bool* enter_event_mode, bool* terminate) = 0;

  // Co-Simulation: one communication step from `time_s`. `terminate` is set
  // when the FMU asks to end the simulation.
  virtual CallStatus DoStep(double time_s, double step_s, bool* terminate) = 0;

  // The FMU's name of `call` and of `status` ("fmi2GetReal", "fmi3Error").
  virtual const char* FunctionName(Call call) const = 0;
  virtual const char* StatusName(CallStatus status) const = 0;

  // "FUNCTION[ (detail)] returned STATUS at t = T s[ (FMU: messages)]".
  std::string Failure(Call call, CallStatus status, double time_s, const std::string& detail = "") const;
  // The FMU's last few messages of any status, "; "-separated, or "".
  std::string RecentMessages() const;
  // Keeps a message the FMU logged; `status` as the FMU's version names it.
  void Log(const std::string& status, const std::string& category, const std::string& message);

 private:
  std::deque<std::string> messages_;
};

}  // namespace mbopt::fmu
