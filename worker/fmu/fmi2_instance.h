// One instance of an FMU's model (fmi2Instantiate .. fmi2FreeInstance) with
// the logger that keeps the FMU's recent messages, so that a failed call's
// reason says what the model itself reported instead of printing it.
#pragma once

#include <deque>
#include <memory>
#include <string>

#include "worker/fmu/fmi2_api.h"
#include "worker/fmu/fmu.h"

namespace mbopt::fmu {

class Fmi2Instance {
 public:
  // Instantiates the model; component() is null when the FMU refused, and
  // RecentMessages() says why if it logged anything. Held by pointer: the
  // FMU keeps the address of the instance for its logger.
  static std::unique_ptr<Fmi2Instance> Create(const Fmu& fmu);

  Fmi2Instance(const Fmi2Instance&) = delete;
  Fmi2Instance& operator=(const Fmi2Instance&) = delete;
  ~Fmi2Instance();

  fmi2Component component() const { return component_; }
  const Fmi2Functions& f() const { return *functions_; }

  // "CALL returned fmi2Error at t = T s (FMU: messages)"; for a failed call.
  std::string Failure(const std::string& call, fmi2Status status, double time_s) const;
  // The FMU's last few messages of any status, "; "-separated, or "".
  std::string RecentMessages() const;

  void Log(fmi2Status status, const std::string& category, std::string message);

 private:
  explicit Fmi2Instance(const Fmi2Functions* functions) : functions_(functions) {}

  const Fmi2Functions* functions_;
  fmi2CallbackFunctions callbacks_{};
  fmi2Component component_ = nullptr;
  std::deque<std::string> messages_;
};

const char* StatusName(fmi2Status status);

}  // namespace mbopt::fmu
