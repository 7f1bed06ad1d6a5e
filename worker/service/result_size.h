// A result larger than the server takes (mbopt-server --max-message-mb)
// would be refused by gRPC on every try, and the task would come back only
// when its lease expired, with no word of why. The worker reports it as a
// failed analysis naming both sizes instead.
#pragma once

#include <cstdint>

#include "mbopt/v1/service.pb.h"

namespace mbopt::worker {

// Replaces `result` by a failed one (kind service, not retried: another
// worker would produce the same size) when it is larger than
// `max_message_bytes`; returns whether it did. 0: no limit known.
bool FitResultToServerLimit(std::int64_t max_message_bytes, v1::TaskResult* result);

}  // namespace mbopt::worker
