#include "client/report/number_format.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace mbopt::report {
namespace {

TEST(FormatTick, DropsFloatingPointNoise) {
  EXPECT_EQ(FormatTick(0.1 + 0.2, 0.1), "0.3");
  EXPECT_EQ(FormatTick(3 * 0.1, 0.1), "0.3");
}

TEST(FormatTick, ShowsEnoughDecimalsForTheStep) {
  EXPECT_EQ(FormatTick(0.25, 0.25), "0.25");
  EXPECT_EQ(FormatTick(2.5, 2.5), "2.5");
  EXPECT_EQ(FormatTick(250, 50), "250");
  EXPECT_EQ(FormatTick(0.002, 0.001), "0.002");
}

TEST(FormatTick, ZeroIsZeroNotATinyResidue) {
  EXPECT_EQ(FormatTick(1e-17, 0.1), "0.0");
}

TEST(FormatTick, UsesShortExponentsForExtremeMagnitudes) {
  EXPECT_EQ(FormatTick(1e-5, 1e-5), "1e-5");
  EXPECT_EQ(FormatTick(2.5e6, 5e5), "2.5e6");
}

TEST(FormatLogTick, LabelsDecadesReadably) {
  EXPECT_EQ(FormatLogTick(0.001), "0.001");
  EXPECT_EQ(FormatLogTick(100), "100");
  EXPECT_EQ(FormatLogTick(1e-6), "1e-6");
  EXPECT_EQ(FormatLogTick(0.0), "");
}

TEST(FormatValue, SpellsOutMissingAndInfiniteValues) {
  EXPECT_EQ(FormatValue(std::numeric_limits<double>::quiet_NaN(), 6, "n/a"), "n/a");
  EXPECT_EQ(FormatValue(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(FormatValue(252.0), "252");
  EXPECT_EQ(FormatValue(1.5e-9), "1.5e-9");
}

TEST(FormatCoordinate, HasTwoDecimalsAndNoNegativeZero) {
  EXPECT_EQ(FormatCoordinate(12.345), "12.35");
  EXPECT_EQ(FormatCoordinate(-0.001), "0.00");
}

}  // namespace
}  // namespace mbopt::report
