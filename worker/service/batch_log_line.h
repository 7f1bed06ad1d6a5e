// The one line a worker logs per batch of results the server took, at the
// default level: an operator following a worker's log sees it work (which
// jobs, how many analyses, how long they took) without --verbose's line per
// task.
#pragma once

#include <cstdint>
#include <string>

#include "mbopt/v1/service.pb.h"

namespace mbopt::worker {

// E.g. "job-1: 3 results delivered (2 ok, 1 failed), 1.24 s of analysis;
// 57 in all". Jobs are named in their order of first appearance.
// `delivered_in_all`: this worker's delivered results, this batch included.
std::string BatchLogLine(const v1::TaskResults& batch, std::int64_t delivered_in_all);

}  // namespace mbopt::worker
