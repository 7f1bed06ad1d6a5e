#include "server/jobs/job_result.h"

#include "server/slp/best_design.h"

namespace mbopt::jobs {

std::optional<slp::DesignPoint> BestDesignOfRecords(const std::vector<slp::CycleRecord>& records,
                                                    const slp::SlpOptions& options) {
  slp::BestDesign best(options.convergence_violation_tolerance);
  for (const slp::CycleRecord& record : records) best.OfferRecord(record);
  return best.best();
}

}  // namespace mbopt::jobs
