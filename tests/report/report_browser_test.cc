// Renders the synthetic report in headless Chromium (Debian's package,
// installed by deploy/install-deps.sh) and checks what a person would see:
// a screenshot with plots in it, the SVG elements in the parsed DOM, and no
// console errors. Fails, not skips, when Chromium is missing (Debian path
// /usr/bin/chromium, or $MBOPT_CHROMIUM).
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "client/report/job_report_html.h"
#include "tests/report/headless_chromium.h"
#include "tests/report/png_decoder.h"
#include "tests/report/synthetic_report.h"

namespace mbopt::report {
namespace {

namespace fs = std::filesystem;

constexpr int kWidthPx = 1200;
constexpr int kHeightPx = 2000;
// A blank page is ~0 % ink; the report's first 2000 px (summary and four
// plots with grids, lines and text) measured 6.1 %. The bounds leave room for
// font and anti-aliasing differences while catching a blank or black page.
constexpr double kMinInkFraction = 0.02;
constexpr double kMaxInkFraction = 0.5;
// Pixels close to a series colour: anti-aliasing blends line edges with the
// background, the core of a 1.8 px line keeps its colour within this.
constexpr int kColorTolerance = 40;

std::string ReadFile(const fs::path& path) { return testing::ReadWholeFile(path); }

class ReportInBrowser : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(access(testing::ChromiumPath().c_str(), X_OK), 0)
        << testing::ChromiumPath() << " is missing: install it with `bash deploy/install-deps.sh` (Debian package chromium)";
    std::string pattern = (fs::temp_directory_path() / "mbopt-report-XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    page_ = dir_ / "report.html";
    std::ofstream(page_) << RenderJobReportHtml(testing::SyntheticVehicleReport());
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  // Runs Chromium on `page` (default: the report) with a fresh profile and
  // `action` (e.g. --dump-dom); returns its exit status and leaves stdout and
  // stderr in <name>.out and <name>.err.
  int RunChromium(const std::string& action, const std::string& name) { return RunChromium(action, name, page_); }
  int RunChromium(const std::string& action, const std::string& name, const fs::path& page) {
    return testing::RunHeadlessChromium(dir_, action, name, page, kWidthPx, kHeightPx);
  }

  fs::path dir_;
  fs::path page_;
};

int CountNear(const testing::RgbImage& image, int r, int g, int b) {
  return testing::CountPixelsNear(image, r, g, b, kColorTolerance);
}

TEST_F(ReportInBrowser, ScreenshotShowsThePlots) {
  const fs::path shot = dir_ / "shot.png";
  ASSERT_EQ(RunChromium("--screenshot=" + shot.string(), "shot"), 0) << ReadFile(dir_ / "shot.err");
  ASSERT_TRUE(fs::exists(shot)) << ReadFile(dir_ / "shot.err");
  testing::RgbImage image;
  ASSERT_EQ(testing::DecodePng(ReadFile(shot), image), "");
  EXPECT_EQ(image.width, kWidthPx);
  EXPECT_EQ(image.height, kHeightPx);
  const double ink = testing::NonWhiteFraction(image);
  const int blue = CountNear(image, 0x1f, 0x77, 0xb4);  // series 0: F, maxg, maxfout, k1
  const int red = CountNear(image, 0xd6, 0x27, 0x28);   // rejected trial markers, reject thresholds
  std::printf("screenshot %dx%d: non-white fraction %.4f, series-blue pixels %d, red pixels %d\n",
              image.width, image.height, ink, blue, red);
  RecordProperty("non_white_fraction", std::to_string(ink));
  EXPECT_GT(ink, kMinInkFraction);
  EXPECT_LT(ink, kMaxInkFraction);
  EXPECT_GT(blue, 500);  // several polylines of a few hundred px each
  EXPECT_GT(red, 50);
}

TEST_F(ReportInBrowser, ParsedPageHasThePlotsAndNoConsoleErrors) {
  ASSERT_EQ(RunChromium("--dump-dom", "dom"), 0) << ReadFile(dir_ / "dom.err");
  const std::string dom = ReadFile(dir_ / "dom.out");
  int svgs = 0;
  for (std::size_t p = dom.find("<svg"); p != std::string::npos; p = dom.find("<svg", p + 1)) ++svgs;
  EXPECT_EQ(svgs, 5);
  EXPECT_NE(dom.find("<polyline"), std::string::npos);
  EXPECT_NE(dom.find("vehicle &lt;suspension&gt; &amp; \"seat\""), std::string::npos);
  const std::string log = ReadFile(dir_ / "dom.err");
  EXPECT_EQ(log.find("CONSOLE"), std::string::npos) << log;
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;
}

// At a 1280-px-wide window every table fits the page: nothing is cut off on
// the right or needs the page to scroll sideways. Long row names (the
// layout's "<constraint>@t=<time> <side>") are the widest cells. A script
// added to a copy of the page (the report itself has none) measures the
// laid-out boxes and writes them into the DOM that --dump-dom prints.
TEST_F(ReportInBrowser, TablesFitThePageWidthAt1280Px) {
  constexpr int kPageWidthPx = 1280;
  ReportData data = testing::SyntheticVehicleReport();
  for (ReportCycle& r : data.records) {
    if (!r.worst_constraint.empty()) r.worst_constraint = "front_wheel_road_contact_force@t=0.420s lower";
    if (!r.rejection_reason.empty()) r.rejection_reason += "; the move limits shrink by a quarter before the LP is solved again";
  }
  std::string html = RenderJobReportHtml(data);
  const std::string probe =
      "<script>\n"
      "const lines = ['page ' + document.documentElement.scrollWidth + ' ' + window.innerWidth];\n"
      "for (const t of document.querySelectorAll('table')) {\n"
      "  const r = t.getBoundingClientRect();\n"
      "  lines.push('table ' + (t.className || 'plain') + ' ' + Math.ceil(r.right) + ' ' + t.scrollWidth + ' ' + "
      "Math.ceil(t.parentElement.getBoundingClientRect().right));\n"
      "}\n"
      "const pre = document.createElement('pre'); pre.id = 'layout'; pre.textContent = lines.join('\\n');\n"
      "document.body.appendChild(pre);\n"
      "</script>\n";
  html.insert(html.rfind("</body>"), probe);
  const fs::path page = dir_ / "probe.html";
  std::ofstream(page) << html;
  ASSERT_EQ(testing::RunHeadlessChromium(dir_, "--dump-dom", "probe", page, kPageWidthPx, kHeightPx), 0)
      << ReadFile(dir_ / "probe.err");
  const std::string dom = ReadFile(dir_ / "probe.out");
  const std::size_t at = dom.find("<pre id=\"layout\">");
  ASSERT_NE(at, std::string::npos) << ReadFile(dir_ / "probe.err");
  std::istringstream layout(dom.substr(at + 17, dom.find("</pre>", at) - at - 17));
  std::string kind;
  int tables = 0;
  while (layout >> kind) {
    if (kind == "page") {
      int scroll_width = 0, window_width = 0;
      layout >> scroll_width >> window_width;
      EXPECT_EQ(window_width, kPageWidthPx);
      EXPECT_LE(scroll_width, window_width) << "the page scrolls sideways";
    } else {
      std::string name;
      int right = 0, scroll_width = 0, parent_right = 0;
      layout >> name >> right >> scroll_width >> parent_right;
      ++tables;
      EXPECT_LE(right, parent_right) << "table " << name << " is wider than its box";
      EXPECT_LE(right, kPageWidthPx) << "table " << name << " runs off the page";
    }
  }
  EXPECT_GE(tables, 4);  // summary, design, active, cycles
}

// The console check above must be able to fail: a page with a script
// error shows up in the same log the same way.
TEST_F(ReportInBrowser, ConsoleErrorsOfABrokenPageWouldBeSeen) {
  const fs::path bad = dir_ / "bad.html";
  std::ofstream(bad) << "<!DOCTYPE html><html><body><script>undefinedFunction();</script></body></html>";
  ASSERT_EQ(RunChromium("--dump-dom", "bad", bad), 0) << ReadFile(dir_ / "bad.err");
  const std::string log = ReadFile(dir_ / "bad.err");
  EXPECT_NE(log.find("CONSOLE"), std::string::npos) << log;
  EXPECT_NE(log.find("Uncaught ReferenceError"), std::string::npos) << log;
}

}  // namespace
}  // namespace mbopt::report
