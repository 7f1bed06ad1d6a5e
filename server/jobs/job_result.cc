#include "server/jobs/job_result.h"

#include "server/slp/best_design.h"

namespace mbopt::jobs {

std::optional<slp::DesignPoint> BestDesignOfRecords(const std::vector<slp::CycleRecord>& records) {
  slp::BestDesign best;
  for (const slp::CycleRecord& record : records) best.OfferRecord(record);
  return best.best();
}

}  // namespace mbopt::jobs
