#include "server/slp/best_design.h"

#include <cmath>

namespace mbopt::slp {

bool BestDesign::Better(const DesignPoint& a, const DesignPoint& b) const {
  const bool a_feasible = a.max_violation <= 0;
  const bool b_feasible = b.max_violation <= 0;
  if (a_feasible != b_feasible) return a_feasible;
  if (a_feasible) return a.objective < b.objective;
  return a.max_violation < b.max_violation;
}

bool BestDesign::Offer(const DesignPoint& point) {
  if (!std::isfinite(point.objective) || !std::isfinite(point.max_violation)) return false;
  if (best_.has_value() && !Better(point, *best_)) return false;
  best_ = point;
  return true;
}

BestDesign::Taken BestDesign::OfferRecord(const CycleRecord& record) {
  const bool x0 = Offer(DesignPoint{record.x0, record.objective_x0, record.max_violation_x0});
  const bool trial = Offer(DesignPoint{record.x_trial, record.objective_trial, record.max_violation_trial});
  return trial ? Taken::kTrial : x0 ? Taken::kX0 : Taken::kNone;
}

}  // namespace mbopt::slp
