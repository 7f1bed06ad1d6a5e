#include "client/report/plot_axis.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace mbopt::report {
namespace {

// Tick values are multiples of a step; rounding leaves a few ulps.
constexpr double kTickTolerance = 1e-9;

std::vector<std::string> Labels(const PlotAxis& axis) {
  std::vector<std::string> out;
  for (const AxisTick& t : axis.ticks) out.push_back(t.label);
  return out;
}

TEST(LinearAxis, CoversTheDataWithNiceTicks) {
  const PlotAxis axis = MakeLinearAxis(252, 356, 6);
  EXPECT_LE(axis.lo, 252);
  EXPECT_GE(axis.hi, 356);
  ASSERT_GE(axis.ticks.size(), 3u);
  EXPECT_EQ(Labels(axis), (std::vector<std::string>{"250", "275", "300", "325", "350", "375"}));
}

TEST(LinearAxis, CycleNumbersGetIntegerTicks) {
  const PlotAxis axis = MakeLinearAxis(0, 3, 8, 1.0);
  for (const AxisTick& t : axis.ticks) EXPECT_NEAR(t.value, std::round(t.value), kTickTolerance);
  EXPECT_EQ(Labels(axis), (std::vector<std::string>{"0", "1", "2", "3"}));
}

TEST(LinearAxis, ASingleValueIsShownInsideTheRange) {
  const PlotAxis axis = MakeLinearAxis(5, 5, 6);
  EXPECT_LT(axis.lo, 5);
  EXPECT_GT(axis.hi, 5);
  const PlotAxis zero = MakeLinearAxis(0, 0, 6);
  EXPECT_LT(zero.lo, 0);
  EXPECT_GT(zero.hi, 0);
}

TEST(LinearAxis, HugeRangesDoNotOverflow) {
  const PlotAxis axis = MakeLinearAxis(-1e308, 1e308, 6);
  EXPECT_TRUE(std::isfinite(axis.lo));
  EXPECT_TRUE(std::isfinite(axis.hi));
  EXPECT_TRUE(std::isfinite(axis.Fraction(0.0)));
}

TEST(LogAxis, SpansWholeDecades) {
  const PlotAxis axis = MakeLogAxis(0.003, 0.4);
  EXPECT_NEAR(axis.lo, 1e-3, 1e-15);
  EXPECT_NEAR(axis.hi, 1.0, kTickTolerance);
  EXPECT_NEAR(axis.Fraction(0.01), 1.0 / 3.0, kTickTolerance);
  EXPECT_EQ(axis.ticks.front().label, "0.001");
  EXPECT_EQ(axis.ticks.back().label, "1");
}

TEST(LogAxis, NonPositiveValuesHaveNoPosition) {
  const PlotAxis axis = MakeLogAxis(1e-3, 1);
  EXPECT_TRUE(std::isnan(axis.Fraction(0.0)));
  EXPECT_TRUE(std::isnan(axis.Fraction(-1.0)));
  EXPECT_TRUE(std::isnan(axis.Fraction(std::nan(""))));
}

TEST(LogAxis, ManyDecadesThinOutTheTicks) {
  const PlotAxis axis = MakeLogAxis(1e-12, 1e4);
  EXPECT_LE(axis.ticks.size(), 9u);
}

TEST(SpansDecades, LooksOnlyAtPositiveFiniteValues) {
  EXPECT_TRUE(SpansDecades({0.5, 0.001, -3.0, 0.0, std::nan("")}));
  EXPECT_FALSE(SpansDecades({0.5, 0.01, -300.0}));
  EXPECT_FALSE(SpansDecades({}));
}

}  // namespace
}  // namespace mbopt::report
