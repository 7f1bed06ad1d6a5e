#include "spec/pareto.h"

#include "common/check.h"

namespace mbopt::spec {
namespace {

void Bisect(int low, int high, std::vector<int>& parent) {
  if (high - low < 2) return;
  const int middle = low + (high - low) / 2;
  // The nearer end; the lower one on a tie, so the chain runs from the
  // objective's own optimum outwards.
  parent[static_cast<size_t>(middle)] = (middle - low <= high - middle) ? low : high;
  Bisect(low, middle, parent);
  Bisect(middle, high, parent);
}

}  // namespace

double ParetoLevel(int k, int points, double value_at_first, double value_at_last) {
  MBOPT_CHECK(points >= 2 && k >= 0 && k < points, "ParetoLevel: point out of range");
  if (k == points - 1) return value_at_last;
  const double t = static_cast<double>(k) / static_cast<double>(points - 1);
  return value_at_first + t * (value_at_last - value_at_first);
}

std::vector<int> ParetoWarmStartParents(int points) {
  std::vector<int> parent(static_cast<size_t>(points < 0 ? 0 : points), -1);
  if (points >= 3) Bisect(0, points - 1, parent);
  return parent;
}

std::vector<bool> DominatedPoints(const std::vector<FrontPoint>& points) {
  std::vector<bool> dominated(points.size(), false);
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].usable) continue;
    for (size_t j = 0; j < points.size() && !dominated[i]; ++j) {
      if (j == i || !points[j].usable) continue;
      const bool no_worse = points[j].first <= points[i].first && points[j].second <= points[i].second;
      const bool better = points[j].first < points[i].first || points[j].second < points[i].second;
      dominated[i] = no_worse && better;
    }
  }
  return dominated;
}

}  // namespace mbopt::spec
