#include "spec/design_set.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

#include "spec/study.h"

namespace mbopt::spec {
namespace {

Study ThreeVariables() {
  Study study;
  for (int i = 0; i < 3; ++i) {
    DesignVariable v;
    v.name = "x" + std::to_string(i);
    v.initial = 1.0 + i;
    v.lower = -2.0 * (i + 1);
    v.upper = 3.0 * (i + 1);
    study.variables.push_back(v);
  }
  return study;
}

TEST(DesignSetTest, LineHasExactEndsAndHoldsTheOtherVariables) {
  Study study = ThreeVariables();
  study.design_set.form = DesignSet::Form::kSweep;
  study.design_set.axes = {SweepAxis{.variable = 1, .from = 0.1, .to = 0.7, .points = 7}};
  const std::vector<std::vector<double>> points = DesignSetPoints(study);
  ASSERT_EQ(points.size(), 7u);
  EXPECT_EQ(study.design_set.size(), 7);
  EXPECT_EQ(points.front()[1], 0.1);
  EXPECT_EQ(points.back()[1], 0.7);
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(points[i][0], 1.0);
    EXPECT_EQ(points[i][2], 3.0);
    EXPECT_NEAR(points[i][1], 0.1 + 0.1 * static_cast<double>(i), 1e-15);
    if (i > 0) {
      EXPECT_GT(points[i][1], points[i - 1][1]);
    }
  }
}

TEST(DesignSetTest, GridVariesTheFirstAxisSlowest) {
  Study study = ThreeVariables();
  study.design_set.form = DesignSet::Form::kSweep;
  study.design_set.axes = {SweepAxis{.variable = 2, .from = 4, .to = 6, .points = 3},
                           SweepAxis{.variable = 0, .from = -1, .to = 1, .points = 2}};
  const std::vector<std::vector<double>> points = DesignSetPoints(study);
  ASSERT_EQ(points.size(), 6u);
  EXPECT_EQ(study.design_set.size(), 6);
  const std::vector<std::vector<double>> expected = {{-1, 2, 4}, {1, 2, 4}, {-1, 2, 5},
                                                     {1, 2, 5},  {-1, 2, 6}, {1, 2, 6}};
  EXPECT_EQ(points, expected);
}

TEST(DesignSetTest, SinglePointAxisIsItsFrom) {
  SweepAxis axis{.variable = 0, .from = 2.5, .to = 2.5, .points = 1};
  EXPECT_EQ(AxisValue(axis, 0), 2.5);
}

// Every dimension's strata [k/n, (k+1)/n) each hold exactly one point.
TEST(DesignSetTest, LatinHypercubeIsStratifiedInEveryDimension) {
  for (const int count : {1, 2, 7, 50, 333}) {
    const std::vector<std::vector<double>> unit = LatinHypercubeUnit(count, 4, 20261127u + count);
    ASSERT_EQ(unit.size(), static_cast<size_t>(count));
    for (int d = 0; d < 4; ++d) {
      std::set<int> strata;
      for (const std::vector<double>& p : unit) {
        ASSERT_GE(p[d], 0.0);
        ASSERT_LT(p[d], 1.0);
        strata.insert(static_cast<int>(std::floor(p[d] * count)));
      }
      EXPECT_EQ(strata.size(), static_cast<size_t>(count)) << "count " << count << ", dimension " << d;
    }
  }
}

TEST(DesignSetTest, LatinHypercubeDependsOnlyOnItsSeed) {
  EXPECT_EQ(LatinHypercubeUnit(20, 3, 7), LatinHypercubeUnit(20, 3, 7));
  EXPECT_NE(LatinHypercubeUnit(20, 3, 7), LatinHypercubeUnit(20, 3, 8));
  // The dimensions are shuffled independently, not one permutation copied.
  const std::vector<std::vector<double>> unit = LatinHypercubeUnit(20, 2, 7);
  int same_stratum = 0;
  for (const std::vector<double>& p : unit) same_stratum += std::floor(p[0] * 20) == std::floor(p[1] * 20) ? 1 : 0;
  EXPECT_LT(same_stratum, 20);
}

TEST(DesignSetTest, LatinHypercubeDesignsLieWithinTheBounds) {
  Study study = ThreeVariables();
  study.design_set.form = DesignSet::Form::kLatinHypercube;
  study.design_set.latin_hypercube = LatinHypercubeSample{.count = 12, .seed = 42};
  const std::vector<std::vector<double>> points = DesignSetPoints(study);
  ASSERT_EQ(points.size(), 12u);
  for (size_t d = 0; d < 3; ++d) {
    const DesignVariable& v = study.variables[d];
    std::set<int> strata;
    for (const std::vector<double>& x : points) {
      EXPECT_GE(x[d], v.lower);
      EXPECT_LT(x[d], v.upper);
      strata.insert(static_cast<int>(std::floor((x[d] - v.lower) / (v.upper - v.lower) * 12)));
    }
    EXPECT_EQ(strata.size(), 12u);
  }
}

}  // namespace
}  // namespace mbopt::spec
