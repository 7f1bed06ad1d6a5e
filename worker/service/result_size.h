// A result larger than the server takes (mbopt-server --max-result-mb, or
// --max-message-mb for a server that takes no results in pieces) would be
// refused on every try, and the task would come back only when its lease
// expired, with no word of why. The worker reports it as a failed analysis
// naming both sizes instead. A result over the message limit but under the
// result limit goes in pieces (ReportResultInPieces).
#pragma once

#include <cstdint>

#include "mbopt/v1/service.pb.h"

namespace mbopt::worker {

// Replaces `result` by a failed one (kind service, not retried: another
// worker would produce the same size) when it is larger than
// `max_result_bytes` (when that is 0, an older server's: than
// `max_message_bytes`); returns whether it did. Both 0: no limit known.
bool FitResultToServerLimit(std::int64_t max_message_bytes, std::int64_t max_result_bytes, v1::TaskResult* result);

// Whether `bytes` of a message fit one message of the server's (0: no
// limit known), with room for gRPC's framing.
bool FitsOneMessage(std::int64_t bytes, std::int64_t max_message_bytes);

}  // namespace mbopt::worker
