#include "worker/service/result_size.h"

#include "absl/strings/str_format.h"

namespace mbopt::worker {

namespace {
// Room for gRPC's own framing.
constexpr std::int64_t kFramingBytes = 1024;
}  // namespace

bool FitsOneMessage(std::int64_t bytes, std::int64_t max_message_bytes) {
  return max_message_bytes <= 0 || bytes + kFramingBytes <= max_message_bytes;
}

bool FitResultToServerLimit(std::int64_t max_message_bytes, std::int64_t max_result_bytes, v1::TaskResult* result) {
  const bool in_pieces = max_result_bytes > 0;
  const std::int64_t limit = in_pieces ? max_result_bytes : max_message_bytes;
  if (limit <= 0) return false;
  const std::int64_t bytes = static_cast<std::int64_t>(result->ByteSizeLong());
  if (in_pieces ? bytes <= limit : FitsOneMessage(bytes, limit)) return false;
  v1::TaskResult failed;
  failed.set_worker_id(result->worker_id());
  failed.set_task_id(result->task_id());
  failed.set_job_id(result->job_id());
  failed.set_request_id(result->request_id());
  *failed.mutable_counters() = result->counters();
  failed.set_formulation(result->formulation());
  failed.set_ok(false);
  failed.set_retry(false);
  failed.set_failure_kind(v1::ANALYSIS_FAILURE_SERVICE);
  failed.set_failure_reason(absl::StrFormat(
      "the result is %.1f MB, more than the server takes (%.1f MB, mbopt-server %s); "
      "use fewer time points or constraints on time series, or raise the server's limit",
      static_cast<double>(bytes) / (1 << 20), static_cast<double>(limit) / (1 << 20),
      in_pieces ? "--max-result-mb" : "--max-message-mb"));
  *result = std::move(failed);
  return true;
}

}  // namespace mbopt::worker
