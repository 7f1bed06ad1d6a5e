// The checker that the page tests rely on must itself catch broken markup.
#include "tests/report/markup_checker.h"

#include <gtest/gtest.h>

namespace mbopt::report::testing {
namespace {

TEST(MarkupChecker, AcceptsNestedAndSelfClosingTags) {
  EXPECT_EQ(CheckMarkup("<svg a=\"1\"><g><line x1=\"0\"/></g><text>a &amp; b</text></svg>", true), "");
}

TEST(MarkupChecker, RejectsUnclosedAndMisnestedTags) {
  EXPECT_NE(CheckMarkup("<svg><g></svg>", true), "");
  EXPECT_NE(CheckMarkup("<svg><text>", true), "");
  EXPECT_NE(CheckMarkup("</g>", true), "");
}

TEST(MarkupChecker, RejectsUnescapedText) {
  EXPECT_NE(CheckMarkup("<text>a & b</text>", true), "");
  EXPECT_NE(CheckMarkup("<text>a < b</text>", true), "");
  EXPECT_NE(CheckMarkup("<text x=\"a<b\">c</text>", true), "");
  EXPECT_NE(CheckMarkup("<text x=1>c</text>", true), "");
}

TEST(MarkupChecker, KnowsHtmlVoidElementsOnlyOutsideXml) {
  EXPECT_EQ(CheckMarkup("<head><meta charset=\"utf-8\"></head>", false), "");
  EXPECT_NE(CheckMarkup("<head><meta charset=\"utf-8\"></head>", true), "");
}

TEST(MarkupChecker, FindsSvgFragmentsAndTheirCoordinates) {
  const auto svgs = SvgFragments("<p>x</p><svg><circle cx=\"1.00\" cy=\"nan\" fill=\"red\"/></svg><svg></svg>");
  ASSERT_EQ(svgs.size(), 2u);
  EXPECT_EQ(NumericAttributeValues(svgs[0]), (std::vector<std::string>{"1.00", "nan"}));
}

}  // namespace
}  // namespace mbopt::report::testing
