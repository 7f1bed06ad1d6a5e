#include "worker/external/input_template.h"

#include <cstdlib>

#include <gtest/gtest.h>

namespace mbopt::external {
namespace {

TEST(InputTemplate, FillsPlaceholdersWithValuesThatReadBackExactly) {
  const auto filled = FillTemplate("k = {stiffness}\nm = {mass_kg}\n", "in.tmpl", {{"stiffness", 0.1}, {"mass_kg", 3.0}});
  ASSERT_TRUE(filled.ok()) << filled.status();
  EXPECT_EQ(*filled, "k = 0.10000000000000001\nm = 3\n");
  // %.17g is exact: the driver reads back the very double the design holds.
  EXPECT_EQ(std::strtod("0.10000000000000001", nullptr), 0.1);
}

TEST(InputTemplate, KeepsBracesThatAreNoPlaceholderAndUnescapesDoubleBraces) {
  const auto filled = FillTemplate("{\"k\": {k}, \"s\": \"{{k}\", \"x\": { }, \"y\": {1a}}", "in.json", {{"k", -2.5}});
  ASSERT_TRUE(filled.ok()) << filled.status();
  EXPECT_EQ(*filled, "{\"k\": -2.5, \"s\": \"{k}\", \"x\": { }, \"y\": {1a}}");
}

TEST(InputTemplate, PlaceholderWithoutValueNamesTemplateAndLine) {
  const auto filled = FillTemplate("a = {a}\n\nb = {b}\n", "model.in.tmpl", {{"a", 1.0}});
  ASSERT_FALSE(filled.ok());
  EXPECT_EQ(filled.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(filled.status().message().find("model.in.tmpl:3: placeholder {b} has no value"), std::string::npos)
      << filled.status();
}

TEST(InputTemplate, ListsPlaceholdersWithTheirFirstLine) {
  const auto names = TemplatePlaceholders("x {a}\n{b} {a}\n{{c}\n");
  ASSERT_EQ(names.size(), 2u);
  EXPECT_EQ(names.at("a"), 1);
  EXPECT_EQ(names.at("b"), 2);
}

TEST(InputTemplate, FormatsLikePrintfSeventeenDigits) {
  EXPECT_EQ(FormatParameterValue(1e-300), "1e-300");
  EXPECT_EQ(FormatParameterValue(1.0 / 3.0), "0.33333333333333331");
  EXPECT_EQ(FormatParameterValue(-2.0 / 3.0 * 1e-300), "-6.6666666666666668e-301");
  EXPECT_EQ(FormatParameterValue(-0.0), "-0");
  EXPECT_EQ(FormatParameterValue(123456789.0), "123456789");
}

}  // namespace
}  // namespace mbopt::external
