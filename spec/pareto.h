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
// order of results. `refine_again: R2` adds R2 more, numbered N+R+1 on,
// once those N+R points have ended, each halving a segment of the front
// they all make: a second generation chosen the same way.
#pragma once

#include <vector>

namespace mbopt::spec {

inline constexpr int kDefaultParetoPoints = 9;
inline constexpr int kMinParetoPoints = 3;
inline constexpr int kMaxParetoPoints = 65;
// A front of three objectives: levels per bounded objective.
inline constexpr int kDefaultParetoGridLevels = 5;
inline constexpr int kMinParetoGridLevels = 2;
inline constexpr int kMaxParetoGridLevels = 9;
// A front of three objectives has its three anchors first (points 0, 1, 2:
// each objective's own optimum), then the grid, level i of the second
// objective and level j of the third at 3 + i * levels + j.
inline constexpr int kParetoAnchorsOfThree = 3;

struct Pareto {
  // The second objective: constraint `constraint`'s largest value, or
  // (trades_objective) Study::second_objective.
  int constraint = -1;  // index into Study::constraints; -1: none
  // The third objective, constraint `third_constraint`'s largest value;
  // -1: a front of two objectives.
  int third_constraint = -1;
  bool trades_objective = false;
  int points = 0;       // the two anchors included; with three objectives, levels per bounded objective
  int refine = 0;       // points added where the front bends, 0 to points-1
  // Points added where the refined front (points + refine) bends, 0 to
  // points + refine - 1; only with refine > 0.
  int refine_again = 0;

  bool three_objectives() const { return third_constraint >= 0; }
  int total_points() const {
    return three_objectives() ? kParetoAnchorsOfThree + points * points : points + refine + refine_again;
  }

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

// A front of three objectives: level i (0 to levels-1) of a bounded
// objective, strictly between its value `upper` (the largest any anchor
// has, where the bound starts to matter) and its own least value `lower`:
// upper - (i + 1) / (levels + 1) * (upper - lower). The anchors hold the
// ends, and a level at the least value itself would leave one design.
double ParetoGridLevel(int i, int levels, double upper, double lower);

// parent[k] of a front of three objectives' points (anchors first, then
// the grid by rows): -1 for the anchors (the study's initial design); grid
// point (0, 0) from anchor 0, the objective's own optimum; (0, j) from
// (0, j-1); (i, j) from (i-1, j). Each bound is tightened one level from a
// point that already meets the other; the first row is a chain, and each
// later row a generation whose points run side by side.
std::vector<int> ParetoGridWarmStartParents(int levels);

// A point of a front as the client sees it: both objectives (minimized),
// and whether its run gave a usable, feasible result. `third`: the third
// objective of a front of three (minimized), 0 on a front of two.
struct FrontPoint {
  double first = 0;
  double second = 0;
  bool usable = false;
  double third = 0;
};

// dominated[k]: usable point k is dominated by another usable point (no
// worse in every objective and better in one). Unusable points: false.
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
