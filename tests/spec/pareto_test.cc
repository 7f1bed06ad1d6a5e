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

TEST(DominatedPoints, OnAFrontOfThreeAPointBeatenInTwoObjectivesButNotTheThirdIsNotDominated) {
  const std::vector<FrontPoint> points = {
      {1.0, 1.0, true, 3.0}, {2.0, 2.0, true, 1.0}, {2.0, 2.0, true, 3.0}, {1.0, 1.0, true, 3.0}};
  // Point 2 is beaten by 1 in the first two, not in the third; point 3 by
  // 1 in all; 1 and 4 repeat each other.
  EXPECT_EQ(DominatedPoints(points), (std::vector<bool>{false, false, true, false}));
}

TEST(ParetoGrid, LevelsLieStrictlyBetweenTheEndsAndTheGridGrowsFromTheObjectivesOwnOptimum) {
  EXPECT_DOUBLE_EQ(ParetoGridLevel(0, 3, 5.0, 1.0), 4.0);
  EXPECT_DOUBLE_EQ(ParetoGridLevel(1, 3, 5.0, 1.0), 3.0);
  EXPECT_DOUBLE_EQ(ParetoGridLevel(2, 3, 5.0, 1.0), 2.0);
  // Anchors 0 to 2 from the initial design; (0, 0) = 3 from anchor 0,
  // (0, 1) = 4 from 3, (1, 0) = 5 from 3, (1, 1) = 6 from 4.
  EXPECT_EQ(ParetoGridWarmStartParents(2), (std::vector<int>{-1, -1, -1, 0, 3, 3, 4}));
}

// An L-shaped front with its knee at (0.1, 0.1): the turn there is nearly a
// right angle, the turns elsewhere a few hundredths of a radian, so the two
// segments that meet at the knee score about 0.95 and the outer ones, though
// longer, about 0.52.
const std::vector<FrontPoint> kKneeFront = {
    {0.0, 1.0, true}, {0.05, 0.5, true}, {0.1, 0.1, true}, {0.5, 0.05, true}, {1.0, 0.0, true}};

TEST(RefinementSegments, HalveTheSegmentsThatMeetAtTheKnee) {
  const std::vector<RefinementSegment> chosen = RefinementSegments(kKneeFront, 2);
  ASSERT_EQ(chosen.size(), 2u);
  EXPECT_EQ(chosen[0].from, 1);
  EXPECT_EQ(chosen[0].to, 2);
  EXPECT_EQ(chosen[1].from, 2);
  EXPECT_EQ(chosen[1].to, 3);
  EXPECT_GT(chosen[0].score, 0.9);
}

TEST(RefinementSegments, ATieGoesToTheSegmentNearerTheFirstAnchor) {
  const std::vector<FrontPoint> even = {{0.0, 1.0, true}, {0.5, 0.5, true}, {1.0, 0.0, true}};
  const std::vector<RefinementSegment> chosen = RefinementSegments(even, 1);
  ASSERT_EQ(chosen.size(), 1u);
  EXPECT_EQ(chosen[0].from, 0);
  EXPECT_EQ(chosen[0].to, 1);
}

TEST(RefinementSegments, AStraightFrontIsHalvedWhereItsGapIsLargest) {
  const std::vector<FrontPoint> line = {{0.0, 1.0, true}, {0.2, 0.8, true}, {0.9, 0.1, true}, {1.0, 0.0, true}};
  const std::vector<RefinementSegment> chosen = RefinementSegments(line, 1);
  ASSERT_EQ(chosen.size(), 1u);
  EXPECT_EQ(chosen[0].from, 1);
  EXPECT_EQ(chosen[0].to, 2);
}

TEST(RefinementSegments, LeaveOutUnusableAndDominatedPointsAndFollowTheFrontsOrder) {
  // Given out of order, with a failed point and a dominated one: the front
  // is points 4, 0, 2 in decreasing second objective.
  const std::vector<FrontPoint> points = {
      {0.5, 0.5, true}, {0.3, 0.3, false}, {1.0, 0.0, true}, {0.6, 0.6, true}, {0.0, 1.0, true}};
  const std::vector<RefinementSegment> chosen = RefinementSegments(points, 5);
  ASSERT_EQ(chosen.size(), 2u);
  EXPECT_EQ(chosen[0].from, 4);
  EXPECT_EQ(chosen[0].to, 0);
  EXPECT_EQ(chosen[1].from, 0);
  EXPECT_EQ(chosen[1].to, 2);
  EXPECT_TRUE(RefinementSegments({{0.0, 1.0, true}}, 3).empty());
}

}  // namespace
}  // namespace mbopt::spec
