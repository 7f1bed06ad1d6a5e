// The unit table: factors against their exact definitions.
#include "spec/units.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace mbopt::spec {
namespace {

// Factors are products of exact constants; only rounding differs.
constexpr double kRelative = 1e-14;

double Factor(const std::string& name) {
  auto unit = FindUnit(name);
  EXPECT_TRUE(unit.ok()) << unit.status();
  return unit.ok() ? unit->si_per_unit : 0.0;
}

TEST(Units, ImperialFactorsFollowTheirExactDefinitions) {
  const double inch = 0.0254, lbf = 0.45359237 * 9.80665;
  EXPECT_NEAR(Factor("in"), inch, kRelative * inch);
  EXPECT_NEAR(Factor("ft"), 12 * inch, kRelative);
  EXPECT_NEAR(Factor("lbf"), lbf, kRelative * lbf);
  EXPECT_NEAR(Factor("lbf/in"), lbf / inch, kRelative * lbf / inch);
  EXPECT_NEAR(Factor("lbf s/in"), lbf / inch, kRelative * lbf / inch);
  EXPECT_NEAR(Factor("lbf s^2/in"), lbf / inch, kRelative * lbf / inch);
  EXPECT_NEAR(Factor("lbf in s^2"), lbf * inch, kRelative * lbf * inch);
  EXPECT_NEAR(Factor("psi"), lbf / (inch * inch), kRelative * 7000);
  EXPECT_NEAR(Factor("in^2"), inch * inch, kRelative);
  EXPECT_NEAR(Factor("in/s^2"), inch, kRelative);
}

TEST(Units, MetricAndAngleFactors) {
  EXPECT_DOUBLE_EQ(Factor("mm"), 1e-3);
  EXPECT_DOUBLE_EQ(Factor("cm"), 1e-2);
  EXPECT_DOUBLE_EQ(Factor("g"), 1e-3);
  EXPECT_DOUBLE_EQ(Factor("MPa"), 1e6);
  EXPECT_DOUBLE_EQ(Factor("GPa"), 1e9);
  EXPECT_DOUBLE_EQ(Factor("mm^2"), 1e-6);
  EXPECT_DOUBLE_EQ(Factor("ms"), 1e-3);
  EXPECT_NEAR(Factor("deg"), 3.14159265358979323846 / 180, 1e-17);
  for (const char* si : {"", "m", "kg", "N", "N/m", "N s/m", "kg m^2", "Pa", "m^2", "kg/m^3", "s",
                         "rad", "rad/s", "m/s", "m/s^2"}) {
    EXPECT_EQ(Factor(si), 1.0) << si;  // exactly 1: SI passes through unchanged
  }
}

TEST(Units, SurroundingSpacesAreIgnored) { EXPECT_EQ(Factor(" mm "), 1e-3); }

TEST(Units, UnknownUnitIsNotFoundAndListsTheKnownOnes) {
  auto unit = FindUnit("furlong");
  ASSERT_FALSE(unit.ok());
  EXPECT_EQ(unit.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(std::string(unit.status().message()), ::testing::HasSubstr("\"furlong\""));
  EXPECT_THAT(std::string(unit.status().message()), ::testing::HasSubstr("\"lbf/in\""));
}

TEST(Units, DimensionsGuardAgainstMixingQuantities) {
  EXPECT_TRUE(UnitFits(*FindUnit("in"), Dimension::kLength));
  EXPECT_FALSE(UnitFits(*FindUnit("in"), Dimension::kAcceleration));
  EXPECT_TRUE(UnitFits(*FindUnit(""), Dimension::kAcceleration));
}

}  // namespace
}  // namespace mbopt::spec
