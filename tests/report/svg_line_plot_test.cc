#include "client/report/svg_line_plot.h"

#include <cmath>
#include <regex>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/report/markup_checker.h"

namespace mbopt::report {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

int Count(const std::string& haystack, const std::string& needle) {
  return testing::CountOccurrences(haystack, needle);
}

void ExpectCoordinatesAreNumbers(const std::string& svg) {
  static const std::regex kNumbers("^[-0-9., ]*$");
  for (const std::string& v : testing::NumericAttributeValues(svg)) {
    EXPECT_TRUE(std::regex_match(v, kNumbers)) << "attribute value '" << v << "'";
  }
}

PlotSpec OneSeries(std::vector<double> x, std::vector<double> y) {
  PlotSpec spec;
  spec.title = "t";
  PlotSeries s;
  s.name = "s";
  s.x = std::move(x);
  s.y = std::move(y);
  spec.series.push_back(s);
  return spec;
}

TEST(SvgLinePlot, IsWellFormedXml) {
  const std::string svg = RenderLinePlotSvg(OneSeries({0, 1, 2}, {3, 1, 2}));
  EXPECT_EQ(testing::CheckMarkup(svg, /*xml_strict=*/true), "");
}

TEST(SvgLinePlot, NanBreaksTheLineInsteadOfReachingTheCoordinates) {
  const double nan = std::nan("");
  const std::string svg = RenderLinePlotSvg(OneSeries({0, 1, 2, 3, 4}, {1, 2, nan, 3, 4}));
  EXPECT_EQ(Count(svg, "<polyline"), 2);  // 0-1 and 3-4
  EXPECT_EQ(testing::CheckMarkup(svg, true), "");
  ExpectCoordinatesAreNumbers(svg);
}

TEST(SvgLinePlot, InfiniteValuesAreGapsToo) {
  const double inf = std::numeric_limits<double>::infinity();
  const std::string svg = RenderLinePlotSvg(OneSeries({0, 1, 2, inf}, {1, inf, 2, 3}));
  ExpectCoordinatesAreNumbers(svg);
  EXPECT_EQ(Count(svg, "<polyline"), 0);  // no two neighbouring usable points
  EXPECT_EQ(Count(svg, "<circle"), 2 + 1);  // two data markers and the legend's
}

TEST(SvgLinePlot, LogAxisPutsNonPositiveValuesOnTheBottomEdge) {
  PlotSpec spec = OneSeries({0, 1, 2, 3}, {0.3, 0.0, -0.1, 0.001});
  spec.log_y = true;
  const std::string svg = RenderLinePlotSvg(spec);
  EXPECT_EQ(Count(svg, "<polygon"), 2);
  EXPECT_THAT(svg, HasSubstr("value \u2264 0"));
  EXPECT_THAT(svg, HasSubstr("(log scale)"));
  ExpectCoordinatesAreNumbers(svg);
}

TEST(SvgLinePlot, LogAxisWithoutPositiveValuesFallsBackToLinear) {
  PlotSpec spec = OneSeries({0, 1}, {-0.3, -0.1});
  spec.log_y = true;
  const std::string svg = RenderLinePlotSvg(spec);
  EXPECT_THAT(svg, Not(HasSubstr("(log scale)")));
  EXPECT_EQ(Count(svg, "<polyline"), 1);
}

TEST(SvgLinePlot, WithoutDataSaysSo) {
  const std::string svg = RenderLinePlotSvg(OneSeries({}, {}));
  EXPECT_THAT(svg, HasSubstr("no data to plot"));
  EXPECT_EQ(testing::CheckMarkup(svg, true), "");
}

TEST(SvgLinePlot, ASinglePointIsAMarker) {
  const std::string svg = RenderLinePlotSvg(OneSeries({1}, {252}));
  EXPECT_EQ(Count(svg, "<polyline"), 0);
  EXPECT_EQ(Count(svg, "<circle"), 2);  // the point and the legend
  ExpectCoordinatesAreNumbers(svg);
}

TEST(SvgLinePlot, ReferenceLinesAreDashedAndWidenTheRange) {
  PlotSpec spec = OneSeries({0, 1}, {0.01, 0.02});
  spec.reference_lines.push_back({0.40, "0.40 reject above", "#d62728", true});
  const std::string svg = RenderLinePlotSvg(spec);
  EXPECT_THAT(svg, HasSubstr("stroke-dasharray=\"6 4\""));
  EXPECT_THAT(svg, HasSubstr("0.40 reject above"));
}

TEST(SvgLinePlot, EscapesNamesAndTitles) {
  PlotSpec spec = OneSeries({0, 1}, {1, 2});
  spec.title = "a<b & \"c\"";
  spec.series[0].name = "x<1> & 'y'";
  const std::string svg = RenderLinePlotSvg(spec);
  EXPECT_THAT(svg, HasSubstr("a&lt;b &amp; &quot;c&quot;"));
  EXPECT_THAT(svg, HasSubstr("x&lt;1&gt; &amp; &#39;y&#39;"));
  EXPECT_EQ(testing::CheckMarkup(svg, true), "");
}

TEST(SvgLinePlot, LeavesSeriesWithoutPointsOutOfTheLegend) {
  PlotSpec spec = OneSeries({0, 1}, {1, 2});
  PlotSeries empty;
  empty.name = "never drawn";
  spec.series.push_back(empty);
  EXPECT_THAT(RenderLinePlotSvg(spec), Not(HasSubstr("never drawn")));
}

TEST(SvgLinePlot, ReferenceLabelsCanSitAtTheLeft) {
  PlotSpec spec = OneSeries({0, 1}, {1, 2});
  spec.reference_lines.push_back({1.5, "left label", "#888888", true, true});
  EXPECT_THAT(RenderLinePlotSvg(spec), HasSubstr("text-anchor=\"start\" class=\"ref-label\">left label"));
}

TEST(SvgLinePlot, CutsLongLegendNamesAtACharacterBoundary) {
  PlotSpec spec = OneSeries({0, 1}, {1, 2});
  spec.series[0].name = "\u00e9\u00e9\u00e9\u00e9\u00e9\u00e9\u00e9\u00e9\u00e9\u00e9"
                        "\u00e9\u00e9\u00e9\u00e9\u00e9\u00e9\u00e9\u00e9\u00e9\u00e9 & tail <x>";
  const std::string svg = RenderLinePlotSvg(spec);
  EXPECT_EQ(testing::CheckMarkup(svg, true), "");
  // 24 characters shown (20 two-byte ones, " &amp; t"), the full name as a tooltip.
  EXPECT_THAT(svg, HasSubstr("\u00e9\u00e9 &amp; t\u2026</text>"));
  EXPECT_THAT(svg, HasSubstr("&amp; tail &lt;x&gt;</title>"));
}

TEST(SvgLinePlot, HollowMarkersAreWhiteInside) {
  PlotSpec spec = OneSeries({1}, {2});
  spec.series[0].marker = MarkerShape::kHollowCircle;
  spec.series[0].color = "#d62728";
  const std::string svg = RenderLinePlotSvg(spec);
  EXPECT_THAT(svg, HasSubstr("fill=\"white\" stroke=\"#d62728\""));
}

TEST(SvgLinePlot, GrowsForALongLegend) {
  PlotSpec spec;
  for (int i = 0; i < 30; ++i) {
    PlotSeries s;
    s.name = "v" + std::to_string(i);
    s.x = {0, 1};
    s.y = {0, static_cast<double>(i)};
    spec.series.push_back(s);
  }
  spec.height_px = 200;
  const std::string svg = RenderLinePlotSvg(spec);
  const std::smatch m = [&] {
    std::smatch match;
    std::regex_search(svg, match, std::regex("height=\"([0-9.]+)\""));
    return match;
  }();
  ASSERT_EQ(m.size(), 2u);
  EXPECT_GT(std::stod(m[1].str()), 30 * 18.0);
}

}  // namespace
}  // namespace mbopt::report

namespace mbopt::report {
namespace {

// x1 and x2 of the first <line> drawn in `color`.
std::pair<double, double> LineEnds(const std::string& svg, const std::string& color) {
  static const std::regex kLine("<line x1=\"([-0-9.]+)\" y1=\"[-0-9.]+\" x2=\"([-0-9.]+)\" y2=\"[-0-9.]+\" stroke=\"");
  for (std::sregex_iterator it(svg.begin(), svg.end(), kLine), end; it != end; ++it) {
    if (svg.compare(static_cast<std::size_t>(it->position() + it->length()), color.size(), color) == 0) {
      return {std::stod((*it)[1]), std::stod((*it)[2])};
    }
  }
  return {std::nan(""), std::nan("")};
}

// The plot area of a 1000-px plot runs from 78 px to 780 px (the legend
// column is the rest); an axis over [0, 10] puts x = 4 at 78 + 0.4 * 702.
constexpr double kLeftPx = 78.0, kRightPx = 780.0;
constexpr double kPxTolerance = 0.01;  // coordinates are written with two decimals

TEST(SvgLinePlot, AReferenceLineSpansTheWholeAxisByDefault) {
  PlotSpec spec = OneSeries({0, 10}, {0, 2});
  spec.reference_lines.push_back({1.0, "limit", "#d62728"});
  const auto [x1, x2] = LineEnds(RenderLinePlotSvg(spec), "#d62728");
  EXPECT_NEAR(x1, kLeftPx, kPxTolerance);
  EXPECT_NEAR(x2, kRightPx, kPxTolerance);
}

TEST(SvgLinePlot, AReferenceLineWithASpanIsDrawnOverItOnly) {
  PlotSpec spec = OneSeries({0, 10}, {0, 2});
  ReferenceLine line{1.0, "limit over 4..6 s", "#d62728"};
  line.x_from = 4.0;
  line.x_to = 6.0;
  spec.reference_lines.push_back(line);
  const std::string svg = RenderLinePlotSvg(spec);
  const auto [x1, x2] = LineEnds(svg, "#d62728");
  EXPECT_NEAR(x1, kLeftPx + 0.4 * (kRightPx - kLeftPx), kPxTolerance);
  EXPECT_NEAR(x2, kLeftPx + 0.6 * (kRightPx - kLeftPx), kPxTolerance);
  EXPECT_EQ(testing::CheckMarkup(svg, true), "");
}

TEST(SvgLinePlot, AReferenceAtOneInstantIsAMarkedBarThere) {
  PlotSpec spec = OneSeries({0, 10}, {0, 2});
  ReferenceLine line{1.0, "final value limit", "#d62728"};
  line.x_from = line.x_to = 10.0;
  spec.reference_lines.push_back(line);
  const std::string svg = RenderLinePlotSvg(spec);
  const auto [x1, x2] = LineEnds(svg, "#d62728");
  EXPECT_NEAR((x1 + x2) / 2, kRightPx, kPxTolerance);
  EXPECT_LT(x2 - x1, 20.0);
  EXPECT_THAT(svg, HasSubstr("<polygon"));  // the diamond on the value
  EXPECT_THAT(svg, HasSubstr("final value limit"));
}

TEST(SvgLinePlot, AReferenceSpanOutsideTheAxisIsNotDrawn) {
  PlotSpec spec = OneSeries({0, 10}, {0, 2});
  ReferenceLine line{1.0, "elsewhere", "#d62728"};
  line.x_from = 20.0;
  line.x_to = 30.0;
  spec.reference_lines.push_back(line);
  const std::string svg = RenderLinePlotSvg(spec);
  EXPECT_THAT(svg, Not(HasSubstr("elsewhere")));
}

}  // namespace
}  // namespace mbopt::report
