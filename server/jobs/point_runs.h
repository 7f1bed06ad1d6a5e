// What a front's job (ParetoRun, ParetoGridRun) does alike for its points'
// SLP runs: routing analysis requests to the point whose run asked for
// them, and emitting the points' records in the points' order.
//
// A Point type has `run` (a pointer to its slp::SlpOptimizer, null until
// started), `ended`, `record` (its slp::CycleRecord) and `cycles` (its
// run's cycle records, held until the point is emitted).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "server/slp/slp_optimizer.h"

namespace mbopt::jobs {

// Point k's request r travels as k * kPointRequestStride + r: far more
// analyses than one run ever asks for, so ids stay unique across the runs.
inline constexpr std::int64_t kPointRequestStride = 1'000'000'000;

template <typename Point>
std::vector<slp::AnalysisRequest> PendingRequestsOfPoints(const std::vector<Point>& points) {
  std::vector<slp::AnalysisRequest> pending;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Point& point = points[k];
    if (point.run == nullptr || point.ended) continue;
    for (slp::AnalysisRequest request : point.run->PendingRequests()) {
      request.id += static_cast<std::int64_t>(k) * kPointRequestStride;
      pending.push_back(std::move(request));
    }
  }
  return pending;
}

template <typename Point>
bool IsPendingInPoints(const std::vector<Point>& points, std::int64_t request_id) {
  if (request_id < 0) return false;
  const std::int64_t k = request_id / kPointRequestStride;
  if (k >= static_cast<std::int64_t>(points.size())) return false;
  const Point& point = points[static_cast<std::size_t>(k)];
  return point.run != nullptr && !point.ended && point.run->IsPending(request_id % kPointRequestStride);
}

// Moves the records of the points that have ended, in the points' order
// from `*emitted` on and up to the first that has not, into `out`: each
// point's run's cycles, then the point's record with the front's analyses
// counted up to it. The log then does not depend on the order in which
// results arrived.
template <typename Point>
void EmitEndedPointsInOrder(std::vector<Point>* points, std::size_t* emitted, std::vector<slp::CycleRecord>* out) {
  std::int64_t analyses_total = *emitted == 0 ? 0 : (*points)[*emitted - 1].record.analyses_total;
  while (*emitted < points->size() && (*points)[*emitted].ended) {
    Point& point = (*points)[*emitted];
    slp::CycleRecord& r = point.record;
    analyses_total += r.pareto_analyses;
    r.analyses_total = analyses_total;
    for (slp::CycleRecord& cycle : point.cycles) out->push_back(std::move(cycle));
    point.cycles = {};
    out->push_back(r);
    ++*emitted;
  }
}

}  // namespace mbopt::jobs
