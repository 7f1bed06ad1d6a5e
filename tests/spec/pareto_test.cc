// The study-defined parts of a Pareto front (spec/pareto.h): the levels,
// the warm-start chain, and which points are dominated.
#include "spec/pareto.h"

#include <gtest/gtest.h>

namespace mbopt::spec {
namespace {

TEST(ParetoLevel, SpreadsEvenlyFromTheFirstAnchorsValueToTheLast) {
  EXPECT_EQ(ParetoLevel(1, 5, 3.0, 1.0), 2.5);
  EXPECT_EQ(ParetoLevel(2, 5, 3.0, 1.0), 2.0);
  EXPECT_EQ(ParetoLevel(4, 5, 3.0, 1.0), 1.0);
}

TEST(ParetoWarmStartParents, BisectsTheRangeFromTheAnchors) {
  // 9 points: 4 from 0; 2 from 0 and 6 from 4; 1, 3, 5, 7 from their lower
  // neighbours.
  EXPECT_EQ(ParetoWarmStartParents(9), (std::vector<int>{-1, 0, 0, 2, 0, 4, 4, 6, -1}));
  EXPECT_EQ(ParetoWarmStartParents(3), (std::vector<int>{-1, 0, -1}));
  // 4 points: 1 from 0, then 2 from 1 (the nearer end of [1, 3]).
  EXPECT_EQ(ParetoWarmStartParents(4), (std::vector<int>{-1, 0, 1, -1}));
}

TEST(DominatedPoints, MarksAPointAnotherBeatsInOneObjectiveAndMatchesInTheOther) {
  const std::vector<FrontPoint> points = {
      {1.0, 3.0, true}, {2.0, 2.0, true}, {2.0, 2.5, true}, {0.5, 0.5, false}, {3.0, 1.0, true}};
  EXPECT_EQ(DominatedPoints(points), (std::vector<bool>{false, false, true, false, false}));
}

}  // namespace
}  // namespace mbopt::spec
