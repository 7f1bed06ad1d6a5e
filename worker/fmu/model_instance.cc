#include "worker/fmu/model_instance.h"

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace mbopt::fmu {
namespace {

// How many of the FMU's messages a failure reason carries: the last ones
// say why; the reason must stay short enough for the analysis record.
constexpr std::size_t kMessagesKept = 4;

}  // namespace

const char* InterfaceName(Interface interface) {
  return interface == Interface::kModelExchange ? "Model Exchange" : "Co-Simulation";
}

void ModelInstance::Log(const std::string& status, const std::string& category, const std::string& message) {
  messages_.push_back(
      absl::StrCat(status, category.empty() ? "" : absl::StrCat(" [", category, "]"), ": ", message));
  if (messages_.size() > kMessagesKept) messages_.pop_front();
}

std::string ModelInstance::RecentMessages() const { return absl::StrJoin(messages_, "; "); }

std::string ModelInstance::Failure(Call call, CallStatus status, double time_s, const std::string& detail) const {
  std::string reason = absl::StrCat(FunctionName(call), detail.empty() ? "" : absl::StrCat(" (", detail, ")"),
                                    " returned ", StatusName(status), " at t = ", time_s, " s");
  if (!messages_.empty()) absl::StrAppend(&reason, " (FMU: ", RecentMessages(), ")");
  return reason;
}

}  // namespace mbopt::fmu
