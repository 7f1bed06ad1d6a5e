// Spot checks (mbopt-server --verify-fraction): a share of the analyses is
// computed by two workers before the optimizer sees it, and a result two
// workers agree on, bit for bit, is the one taken. Which analyses are checked
// depends only on the job's id and the analysis' request id, so a resume or
// another number of workers checks the same ones; and since the value taken
// is the one honest workers compute, a run with checks gives the records of
// a run without them.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "server/jobs/analysis_record.h"

namespace mbopt::jobs::manager {

// Whether analysis `request_id` of job `job_id` is checked when a share
// `fraction` (0 to 1) of analyses is: a hash of both, read as a number in
// [0, 1), below the fraction.
bool SpotChecked(std::string_view job_id, std::int64_t request_id, double fraction);

// Whether two answers to the same analysis agree: the same outcome (ok, or
// the same failure kind) and the same bits in every value and gradient.
// Running time, counters and failure texts may differ between machines.
bool SameAnswer(const AnalysisRecord& a, const AnalysisRecord& b);

// One worker's answer to a checked analysis, held until another agrees.
struct SpotCheckOpinion {
  AnalysisRecord record;
  std::string worker_id;  // full id (the scheduler's)
};

// The most answers asked for one analysis; past it, with no two agreeing,
// the analysis is taken as failed.
inline constexpr int kMaxSpotCheckOpinions = 5;

}  // namespace mbopt::jobs::manager
