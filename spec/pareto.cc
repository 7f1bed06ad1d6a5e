#include "spec/pareto.h"

#include <algorithm>
#include <cmath>
#include <numeric>

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

double ParetoGridLevel(int i, int levels, double upper, double lower) {
  MBOPT_CHECK(levels >= 1 && i >= 0 && i < levels, "ParetoGridLevel: level out of range");
  const double t = static_cast<double>(i + 1) / static_cast<double>(levels + 1);
  return upper - t * (upper - lower);
}

std::vector<int> ParetoGridWarmStartParents(int levels) {
  const int n = levels < 0 ? 0 : levels;
  std::vector<int> parent(static_cast<size_t>(kParetoAnchorsOfThree + n * n), -1);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const int k = kParetoAnchorsOfThree + i * n + j;
      int from = 0;
      if (i > 0) {
        from = k - n;
      } else if (j > 0) {
        from = k - 1;
      }
      parent[static_cast<size_t>(k)] = from;
    }
  }
  return parent;
}

std::vector<bool> DominatedPoints(const std::vector<FrontPoint>& points) {
  std::vector<bool> dominated(points.size(), false);
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].usable) continue;
    for (size_t j = 0; j < points.size() && !dominated[i]; ++j) {
      if (j == i || !points[j].usable) continue;
      const bool no_worse = points[j].first <= points[i].first && points[j].second <= points[i].second &&
                            points[j].third <= points[i].third;
      const bool better = points[j].first < points[i].first || points[j].second < points[i].second ||
                          points[j].third < points[i].third;
      dominated[i] = no_worse && better;
    }
  }
  return dominated;
}

std::vector<RefinementSegment> RefinementSegments(const std::vector<FrontPoint>& points, int count) {
  const std::vector<bool> dominated = DominatedPoints(points);
  std::vector<int> front;
  for (size_t k = 0; k < points.size(); ++k) {
    if (points[k].usable && !dominated[k] && std::isfinite(points[k].first) && std::isfinite(points[k].second)) {
      front.push_back(static_cast<int>(k));
    }
  }
  // Decreasing second objective: from the first objective's own optimum.
  std::stable_sort(front.begin(), front.end(), [&](int a, int b) {
    return points[static_cast<size_t>(a)].second > points[static_cast<size_t>(b)].second;
  });
  if (front.size() < 2 || count <= 0) return {};
  double first_low = points[static_cast<size_t>(front[0])].first, first_high = first_low;
  double second_low = points[static_cast<size_t>(front[0])].second, second_high = second_low;
  for (int k : front) {
    first_low = std::min(first_low, points[static_cast<size_t>(k)].first);
    first_high = std::max(first_high, points[static_cast<size_t>(k)].first);
    second_low = std::min(second_low, points[static_cast<size_t>(k)].second);
    second_high = std::max(second_high, points[static_cast<size_t>(k)].second);
  }
  // A flat objective (one value on the whole front) does not stretch the
  // other: its range counts as 1.
  const double first_range = first_high > first_low ? first_high - first_low : 1.0;
  const double second_range = second_high > second_low ? second_high - second_low : 1.0;
  const size_t segments = front.size() - 1;
  std::vector<double> du(segments), dv(segments), length(segments);
  for (size_t s = 0; s < segments; ++s) {
    const FrontPoint& a = points[static_cast<size_t>(front[s])];
    const FrontPoint& b = points[static_cast<size_t>(front[s + 1])];
    du[s] = (b.first - a.first) / first_range;
    dv[s] = (b.second - a.second) / second_range;
    length[s] = std::hypot(du[s], dv[s]);
  }
  std::vector<double> turn(front.size(), 0.0);
  for (size_t j = 1; j + 1 < front.size(); ++j) {
    const double cross = du[j - 1] * dv[j] - dv[j - 1] * du[j];
    const double dot = du[j - 1] * du[j] + dv[j - 1] * dv[j];
    turn[j] = std::abs(std::atan2(cross, dot));
  }
  std::vector<RefinementSegment> all(segments);
  for (size_t s = 0; s < segments; ++s) {
    all[s] = {front[s], front[s + 1], length[s] * (1.0 + turn[s] + turn[s + 1])};
  }
  std::vector<size_t> order(segments);
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return all[a].score > all[b].score; });
  order.resize(std::min(order.size(), static_cast<size_t>(count)));
  std::sort(order.begin(), order.end());
  std::vector<RefinementSegment> chosen;
  for (size_t s : order) chosen.push_back(all[s]);
  return chosen;
}

}  // namespace mbopt::spec
