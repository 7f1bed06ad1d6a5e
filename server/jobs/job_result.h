// A job's result read from its logged cycle records, for a job that is not
// running in this process: the same choice as SlpOptimizer::best_design()
// makes while it runs (server/slp/best_design.h).
#pragma once

#include <optional>
#include <vector>

#include "server/slp/slp_optimizer.h"

namespace mbopt::jobs {

// None when no record holds an analysed design.
std::optional<slp::DesignPoint> BestDesignOfRecords(const std::vector<slp::CycleRecord>& records);

}  // namespace mbopt::jobs
