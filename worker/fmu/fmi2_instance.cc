#include "worker/fmu/fmi2_instance.h"

#include <cstdarg>
#include <cstdio>
#include <cstdlib>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace mbopt::fmu {
namespace {

// How many of the FMU's messages a failure reason carries: the last ones
// say why; the reason must stay short enough for the analysis record.
constexpr std::size_t kMessagesKept = 4;

extern "C" void LogFromFmu(fmi2ComponentEnvironment environment, fmi2String /*instance_name*/, fmi2Status status,
                           fmi2String category, fmi2String message, ...) {
  if (environment == nullptr || message == nullptr) return;
  char text[1024];
  va_list arguments;
  va_start(arguments, message);
  std::vsnprintf(text, sizeof text, message, arguments);
  va_end(arguments);
  static_cast<Fmi2Instance*>(environment)->Log(status, category != nullptr ? category : "", text);
}

extern "C" void* AllocateForFmu(size_t count, size_t size) { return std::calloc(count, size); }
extern "C" void FreeForFmu(void* object) { std::free(object); }

}  // namespace

const char* StatusName(fmi2Status status) {
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

std::unique_ptr<Fmi2Instance> Fmi2Instance::Create(const Fmu& fmu) {
  std::unique_ptr<Fmi2Instance> instance(new Fmi2Instance(&fmu.functions()));
  instance->callbacks_.logger = LogFromFmu;
  instance->callbacks_.allocateMemory = AllocateForFmu;
  instance->callbacks_.freeMemory = FreeForFmu;
  instance->callbacks_.stepFinished = nullptr;
  instance->callbacks_.componentEnvironment = instance.get();
  const fmi2Type type = fmu.interface() == Interface::kModelExchange ? fmi2ModelExchange : fmi2CoSimulation;
  instance->component_ = fmu.functions().instantiate(fmu.interface_type().model_identifier.c_str(), type,
                                                     fmu.description().guid.c_str(), fmu.resource_uri().c_str(),
                                                     &instance->callbacks_, fmi2False, fmi2False);
  return instance;
}

Fmi2Instance::~Fmi2Instance() {
  if (component_ != nullptr) functions_->free_instance(component_);
}

void Fmi2Instance::Log(fmi2Status status, const std::string& category, std::string message) {
  messages_.push_back(absl::StrCat(StatusName(status), category.empty() ? "" : absl::StrCat(" [", category, "]"),
                                   ": ", message));
  if (messages_.size() > kMessagesKept) messages_.pop_front();
}

std::string Fmi2Instance::RecentMessages() const { return absl::StrJoin(messages_, "; "); }

std::string Fmi2Instance::Failure(const std::string& call, fmi2Status status, double time_s) const {
  std::string reason = absl::StrCat(call, " returned ", StatusName(status), " at t = ", time_s, " s");
  if (!messages_.empty()) absl::StrAppend(&reason, " (FMU: ", RecentMessages(), ")");
  return reason;
}

}  // namespace mbopt::fmu
