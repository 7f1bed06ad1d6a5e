// The result of a run: the best design it analysed. The method's own last
// point (SlpOptimizer::current_design) can be worse than an earlier one: an
// accepted step may raise F within the acceptance thresholds, and a rejected
// trial may be better than the point the run ended on.
//
// Order: a feasible design (maxg <= 0: every constraint met, not merely
// within the violation tolerance, which is a stopping criterion and no
// licence for the result) beats an infeasible one; among feasible designs
// the lower F wins, among infeasible ones the lower maxg. Ties keep the
// earlier design, so the choice depends only on the sequence of cycle
// records: the optimizer and a reader of the job's logged records make the
// same choice.
#pragma once

#include <optional>

#include <Eigen/Dense>

#include "server/slp/slp_optimizer.h"

namespace mbopt::slp {

class BestDesign {
 public:

  // Offers a design; one whose values are not finite (a failed analysis) is
  // ignored. True when it became the best.
  bool Offer(const DesignPoint& point);
  // Which of a record's designs became the best when offered (x0 first,
  // then the trial point).
  enum class Taken { kNone, kX0, kTrial };
  Taken OfferRecord(const CycleRecord& record);

  const std::optional<DesignPoint>& best() const { return best_; }

 private:
  bool Better(const DesignPoint& a, const DesignPoint& b) const;

  std::optional<DesignPoint> best_;
};

}  // namespace mbopt::slp
