// The drawing page of `mbopt draw` (client/report/mechanism_drawing.h) in
// headless Chromium: the bodies are painted, the script runs without a
// console error and shows the frame the address asks for. Fails, not
// skips, when Chromium is missing (as report_browser_test).
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "client/report/load_case_drawings.h"
#include "client/report/mechanism_drawing.h"
#include "tests/report/headless_chromium.h"
#include "tests/report/markup_checker.h"
#include "tests/report/png_decoder.h"

namespace mbopt::report {
namespace {

namespace fs = std::filesystem;

constexpr int kWidthPx = 800;
constexpr int kHeightPx = 700;
// Pixels close to the bodies' fill (#c9d8f0): anti-aliased edges blend
// with the background, the inside of a 14 px wide bar keeps the colour.
constexpr int kColorTolerance = 12;

// A crank 1 m long turning once over `instants` instants, 1/20 s apart,
// about a hatched ground pin.
spec::SceneDrawing Crank(int instants = 20) {
  spec::SceneDrawing d;
  d.scene_name = "crank";
  const int o = d.AddPoint("O"), a = d.AddPoint("A");
  d.bodies.push_back({"crank", {o, a}});
  d.joints.push_back({"O", spec::SceneDrawing::JointKind::kPin, o, {}});
  d.joints.push_back({"A", spec::SceneDrawing::JointKind::kPin, a, {}});
  d.ground_points.push_back(o);
  for (int i = 0; i < instants; ++i) {
    d.times_s.push_back(0.05 * i);
    const double th = 2 * M_PI * 0.05 * i;
    d.points_m.push_back({{0, 0}, {std::cos(th), std::sin(th)}});
  }
  return d;
}

class DrawingInBrowser : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(access(testing::ChromiumPath().c_str(), X_OK), 0)
        << testing::ChromiumPath()
        << " is missing: install it with `bash deploy/install-deps.sh` (Debian package chromium)";
    std::string pattern = (fs::temp_directory_path() / "mbopt-drawing-XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
    page_ = dir_ / "crank.html";
    std::ofstream(page_) << SceneDrawingPageHtml(Crank(), "crank.scene.textproto");
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  int Run(const std::string& action, const std::string& name, const std::string& page) {
    return testing::RunHeadlessChromium(dir_, action, name, page, kWidthPx, kHeightPx);
  }
  fs::path dir_, page_;
};

TEST_F(DrawingInBrowser, ScreenshotShowsTheBody) {
  const fs::path shot = dir_ / "shot.png";
  ASSERT_EQ(Run("--screenshot=" + shot.string(), "shot", page_.string()), 0)
      << testing::ReadWholeFile(dir_ / "shot.err");
  testing::RgbImage image;
  ASSERT_EQ(testing::DecodePng(testing::ReadWholeFile(shot), image), "");
  const int fill = testing::CountPixelsNear(image, 0xc9, 0xd8, 0xf0, kColorTolerance);
  std::printf("body-fill pixels: %d\n", fill);
  // The crank at t = 0: a bar of about 300 px by 14 px, its outline inside.
  EXPECT_GT(fill, 1500);
}

TEST_F(DrawingInBrowser, ScriptShowsTheFrameTheAddressAsksForWithoutErrors) {
  ASSERT_EQ(Run("--dump-dom", "dom", page_.string() + "#frame=7"), 0) << testing::ReadWholeFile(dir_ / "dom.err");
  const std::string dom = testing::ReadWholeFile(dir_ / "dom.out");
  const std::string log = testing::ReadWholeFile(dir_ / "dom.err");
  EXPECT_EQ(log.find("CONSOLE"), std::string::npos) << log;
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;
  // The 8th frame is the one shown; the first is hidden now.
  std::vector<std::string> frames;
  for (std::size_t p = dom.find("<g class=\"frame\""); p != std::string::npos;
       p = dom.find("<g class=\"frame\"", p + 1)) {
    frames.push_back(dom.substr(p, dom.find('>', p) - p));
  }
  ASSERT_EQ(frames.size(), 20u);
  for (size_t f = 0; f < frames.size(); ++f) {
    EXPECT_EQ(frames[f].find("display=\"none\"") == std::string::npos, f == 7) << "frame " << f << ": " << frames[f];
  }
  EXPECT_NE(dom.find("t = 0.35 s"), std::string::npos);
}

// The <g class="frame"> tags of a page's figures, in the page's order.
std::vector<std::string> FrameTags(const std::string& dom) {
  std::vector<std::string> frames;
  for (std::size_t p = dom.find("<g class=\"frame\""); p != std::string::npos;
       p = dom.find("<g class=\"frame\"", p + 1)) {
    frames.push_back(dom.substr(p, dom.find('>', p) - p));
  }
  return frames;
}

// Load cases' figures share one slider: "#time=0.62" in the address shows
// each figure's instant nearest 0.62 s: 0.6 s on the grid to 0.95 s, the
// last, 0.35 s, on the grid that ends there.
TEST_F(DrawingInBrowser, TheCasesSharedSliderMovesEveryFigure) {
  const fs::path cases = dir_ / "cases.html";
  std::ofstream(cases) << LoadCaseDrawingsPageHtml({CaseDrawing{"long", Crank(20)}, CaseDrawing{"short", Crank(8)}},
                                                   "crank study", "crank.study.textproto");
  ASSERT_EQ(Run("--dump-dom", "cases", cases.string() + "#time=0.62"), 0) << testing::ReadWholeFile(dir_ / "cases.err");
  const std::string dom = testing::ReadWholeFile(dir_ / "cases.out");
  const std::string log = testing::ReadWholeFile(dir_ / "cases.err");
  EXPECT_EQ(log.find("CONSOLE"), std::string::npos) << log;
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;
  const std::vector<std::string> frames = FrameTags(dom);
  ASSERT_EQ(frames.size(), 28u);
  for (size_t f = 0; f < frames.size(); ++f) {
    const bool shown = f == 12 || f == 20 + 7;
    EXPECT_EQ(frames[f].find("display=\"none\"") == std::string::npos, shown) << "frame " << f << ": " << frames[f];
  }
  EXPECT_EQ(testing::CountOccurrences(dom, "t = 0.6 s"), 2) << "the first figure's label and the shared one";
  EXPECT_EQ(testing::CountOccurrences(dom, "t = 0.35 s"), 1) << "the second figure's label";
}

}  // namespace
}  // namespace mbopt::report
