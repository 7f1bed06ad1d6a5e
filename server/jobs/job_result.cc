#include "server/jobs/job_result.h"

#include "server/slp/best_design.h"

namespace mbopt::jobs {

std::optional<slp::DesignPoint> BestDesignOfRecords(const std::vector<slp::CycleRecord>& records) {
  slp::BestDesign best;
  for (const slp::CycleRecord& record : records) {
    // A Pareto point's run's cycles are no designs of the front's: their F
    // and maxg are the run's, against its own level.
    if (record.pareto_point == 0) best.OfferRecord(record);
  }
  return best.best();
}

}  // namespace mbopt::jobs
