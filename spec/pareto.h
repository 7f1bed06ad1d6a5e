// A Pareto front (docs/study.md, "Pareto fronts"): the trade-off between a
// study's objective and a second objective (the largest value of one of its
// constraints, or an objective of its own), by the epsilon-constraint
// method. Point 0 minimizes the objective without the second, point N-1
// minimizes the second (the anchors); point k between minimizes the
// objective with the second bounded at the level ParetoLevel(k). Each point
// is an SLP run.
//
// The warm-start chain is a function of the study alone, never of which run
// ends first: the anchors start from the study's initial design; the other
// points are visited by bisection of the index range (the middle point of
// [0, N-1], then the middle points of both halves, and so on), each started
// from the result of the nearer end of its interval, which is already a
// point of the front. So points of one generation run side by side, and
// the front is the same bit for bit whatever the number of workers.
//
// Refinement (`refine: R`): once the N points have ended, R more points,
// numbered N+1 to N+R, each halving one segment of the front where it bends
// or leaves a gap (RefinementSegments). They are chosen from the first N
// points alone, so they too run side by side and do not depend on the
// order of results.
#pragma once

#include <vector>

namespace mbopt::spec {

inline constexpr int kDefaultParetoPoints = 9;
inline constexpr int kMinParetoPoints = 3;
inline constexpr int kMaxParetoPoints = 65;

struct Pareto {
  // The second objective: constraint `constraint`'s largest value, or
  // (trades_objective) Study::second_objective.
  int constraint = -1;  // index into Study::constraints; -1: none
  bool trades_objective = false;
  int points = 0;       // the two anchors included
  int refine = 0;       // points added where the front bends, 0 to points-1

  int total_points() const { return points + refine; }

  bool enabled() const { return constraint >= 0 || trades_objective; }
};

// The level of the traded constraint for point k of `points` (0 < k <
// points-1), evenly spaced from `value_at_first` (the constraint's value
// where the objective alone is minimized) down to `value_at_last` (its
// least value); both in the same unit.
double ParetoLevel(int k, int points, double value_at_first, double value_at_last);

// parent[k]: the point whose result starts point k's run; -1 for the two
// anchors (they start from the study's initial design).
std::vector<int> ParetoWarmStartParents(int points);

// A point of a front as the client sees it: both objectives (minimized),
// and whether its run gave a usable, feasible result.
struct FrontPoint {
  double first = 0;
  double second = 0;
  bool usable = false;
};

// dominated[k]: usable point k is dominated by another usable point (no
// worse in both objectives and better in one). Unusable points: false.
std::vector<bool> DominatedPoints(const std::vector<FrontPoint>& points);

// A segment of the front to halve: between points `from` and `to` (indices
// into the points given), `from` the one with the larger second objective.
struct RefinementSegment {
  int from = -1;
  int to = -1;
  double score = 0;
};

// The `count` segments of the front where a point adds the most, in the
// front's order (decreasing second objective). The front is the usable,
// non-dominated points in decreasing order of the second objective (ties
// by index); both objectives normalized by their ranges over it. A
// segment's score is its normalized length times (1 + the turn at its two
// ends), the turn at a point being the angle in radians between the
// segments that meet there (0 at the ends of the front): a long segment is
// a gap, a turn is a bend, and a short segment at a sharp knee is not
// chosen again and again. Ties go to the segment nearer the first anchor.
// Fewer than `count` when the front has fewer segments.
std::vector<RefinementSegment> RefinementSegments(const std::vector<FrontPoint>& points, int count);

}  // namespace mbopt::spec
