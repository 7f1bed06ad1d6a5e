// `mbopt-worker draw`: a study's load case drawn with the parameters the
// case sets, checked against the slider crank's closed form; names that
// are not load cases refused with the names there are.
#include "worker/main/draw_command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "mbopt/v1/drawing.pb.h"
#include "spec/io/drawing_convert.h"
#include "worker/main/eval_command.h"

namespace mbopt::worker {
namespace {

using ::testing::HasSubstr;

// Newton closes the press's positions to 1e-11 m (AssemblyOptions); a few
// times that covers round-off of coordinates of order 1 m.
constexpr double kPositionTolerance = 1e-9;

struct DrawRun {
  int code;
  std::string out, err;
};

DrawRun Draw(const std::vector<std::string>& args) {
  std::ostringstream out, err;
  const int code = RunDraw(args, out, err);
  return {code, out.str(), err.str()};
}

spec::SceneDrawing ReadDrawing(const std::string& path) {
  v1::SceneDrawing message;
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(message.ParseFromIstream(&in)) << path;
  absl::StatusOr<spec::SceneDrawing> drawing = spec::io::DrawingFromProto(message);
  EXPECT_TRUE(drawing.ok()) << drawing.status();
  return drawing.ok() ? *drawing : spec::SceneDrawing{};
}

int PointNamed(const spec::SceneDrawing& d, const std::string& name) {
  for (size_t k = 0; k < d.point_names.size(); ++k) {
    if (d.point_names[k] == name) return static_cast<int>(k);
  }
  ADD_FAILURE() << "no point named " << name;
  return 0;
}

// The press (examples/press: crank radius r, rod l, the crank turning at
// pi rad/s from 0) with the crank radius a design variable and two load
// cases: the scene as it is, and a longer rod.
class DrawLoadCase : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "draw_load_case";
    std::filesystem::create_directories(dir);
    study_ = (dir / "press_cases.study.textproto").string();
    out_ = (dir / "drawing.pb").string();
    std::ofstream(study_) << R"pb(name: "press_cases"
scene_file: ")pb" << std::filesystem::absolute("examples/press/press.scene.textproto").string()
                          << R"pb("
variables { name: "r" parameter: "crank_radius" scale: 0.1 initial: 1.2 lower: 1.0 upper: 3.0 }
cases { name: "as_built" }
cases { name: "long_rod" set { parameter: "rod_length" value: 1000 unit: "mm" } }
objective { minimize_max_of: "long_rod.torque" reduction: REDUCTION_MAX_ABS }
)pb";
  }

  // The slider's x at every instant is r cos th + sqrt(l^2 - r^2 sin^2 th).
  static void ExpectSliderCrank(const spec::SceneDrawing& d, double r_m, double l_m) {
    ASSERT_EQ(d.failure, "");
    ASSERT_EQ(d.points_m.size(), 101u);
    const int pin = PointNamed(d, "crank.pin"), slider = PointNamed(d, "slider.pin");
    for (size_t i = 0; i < d.times_s.size(); ++i) {
      const double th = std::numbers::pi * d.times_s[i];
      const auto& at = d.points_m[i];
      EXPECT_NEAR(at[pin].x_m, r_m * std::cos(th), kPositionTolerance) << "t = " << d.times_s[i];
      EXPECT_NEAR(at[slider].x_m, r_m * std::cos(th) + std::sqrt(l_m * l_m - r_m * r_m * std::sin(th) * std::sin(th)),
                  kPositionTolerance)
          << "t = " << d.times_s[i];
    }
  }

  std::string study_, out_;
};

TEST_F(DrawLoadCase, DrawsTheCaseWithTheParametersItSets) {
  const DrawRun long_rod = Draw({study_, "--out", out_, "--case", "long_rod"});
  ASSERT_EQ(long_rod.code, kExitOk) << long_rod.err;
  EXPECT_THAT(long_rod.out, HasSubstr("(load case long_rod)"));
  ExpectSliderCrank(ReadDrawing(out_), 0.12, 1.0);

  // A case that sets nothing is the scene's own rod, at the same design.
  const DrawRun as_built = Draw({study_, "--out", out_, "--case=as_built"});
  ASSERT_EQ(as_built.code, kExitOk) << as_built.err;
  ExpectSliderCrank(ReadDrawing(out_), 0.12, 0.8);

  // The design still moves with --set beside the case.
  const DrawRun longer_crank = Draw({study_, "--out", out_, "--case", "long_rod", "--set", "r=2"});
  ASSERT_EQ(longer_crank.code, kExitOk) << longer_crank.err;
  ExpectSliderCrank(ReadDrawing(out_), 0.2, 1.0);
}

TEST_F(DrawLoadCase, RefusesANameThatIsNotALoadCase) {
  const DrawRun unknown = Draw({study_, "--out", out_, "--case", "short_rod"});
  EXPECT_EQ(unknown.code, kExitBadInput);
  EXPECT_THAT(unknown.err, HasSubstr("--case \"short_rod\" is not a load case of the study; its cases: "
                                     "\"as_built\", \"long_rod\""));
  const DrawRun scene = Draw({"examples/press/press.scene.textproto", "--out", out_, "--case", "long_rod"});
  EXPECT_EQ(scene.code, kExitBadInput);
  EXPECT_THAT(scene.err, HasSubstr("this file has no load cases"));
  const DrawRun no_value = Draw({study_, "--out", out_, "--case"});
  EXPECT_EQ(no_value.code, kExitBadInput);
  EXPECT_THAT(no_value.err, HasSubstr("--case needs a value"));
}

}  // namespace
}  // namespace mbopt::worker
