// The drawings of a study with load cases through the real mbopt-worker:
// the report's "Mechanism" section (client/report_mechanism.h) of a
// hand-made job and `mbopt draw` of the study draw every case with the
// parameters it sets, checked against the slider crank's closed form;
// `mbopt draw` and the report's section of a flexible arm magnify its
// deflection when asked and say so, and say why a kinematic analysis' arm
// is drawn rigid. No server is needed.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "client/commands.h"
#include "client/exit_codes.h"
#include "client/report_mechanism.h"
#include "spec/io/study_io.h"

namespace mbopt::client {
namespace {

using ::testing::HasSubstr;

// Newton closes the press's positions to 1e-11 m (AssemblyOptions); a few
// times that covers round-off of coordinates of order 1 m.
constexpr double kPositionTolerance = 1e-9;

int PointNamed(const spec::SceneDrawing& d, const std::string& name) {
  for (size_t k = 0; k < d.point_names.size(); ++k) {
    if (d.point_names[k] == name) return static_cast<int>(k);
  }
  ADD_FAILURE() << "no point named " << name;
  return 0;
}

// The press (examples/press: the crank turning at pi rad/s from 0): the
// slider at x = r cos th + sqrt(l^2 - r^2 sin^2 th) at every instant.
void ExpectSliderCrank(const std::optional<spec::SceneDrawing>& d, double r_m, double l_m) {
  ASSERT_TRUE(d.has_value());
  ASSERT_EQ(d->failure, "");
  ASSERT_EQ(d->points_m.size(), 101u);
  const int slider = PointNamed(*d, "slider.pin");
  for (size_t i = 0; i < d->times_s.size(); ++i) {
    const double th = std::numbers::pi * d->times_s[i];
    EXPECT_NEAR(d->points_m[i][slider].x_m,
                r_m * std::cos(th) + std::sqrt(l_m * l_m - r_m * r_m * std::sin(th) * std::sin(th)),
                kPositionTolerance)
        << "r = " << r_m << ", l = " << l_m << ", t = " << d->times_s[i];
  }
}

// The press with its crank radius a design variable (from 0.12 m; the
// job's final design 0.2 m) and two load cases: the scene as it is, and a
// rod of 1 m.
class LoadCaseDrawing : public ::testing::Test {
 protected:
  void SetUp() override {
    setenv("MBOPT_WORKER_BIN", MBOPT_TEST_WORKER, 1);
    const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "report_load_cases";
    std::filesystem::create_directories(dir);
    dir_ = dir.string();
    study_path_ = (dir / "press_cases.study.textproto").string();
    std::ofstream(study_path_) << "name: \"press_cases\"\nscene_file: \"" << MBOPT_TEST_SOURCE_DIR
                               << "/examples/press/press.scene.textproto\"\n" << R"pb(
variables { name: "r" parameter: "crank_radius" scale: 0.1 initial: 1.2 lower: 1.0 upper: 3.0 }
cases { name: "as_built" }
cases { name: "long_rod" set { parameter: "rod_length" value: 1000 unit: "mm" } }
objective { minimize_max_of: "long_rod.torque" reduction: REDUCTION_MAX_ABS }
)pb";
    absl::StatusOr<v1::Study> study = spec::io::ReadStudyProto(study_path_);
    ASSERT_TRUE(study.ok()) << study.status();
    *job_.mutable_study() = *study;
    v1::CycleRecord& record = *job_.add_cycles();
    record.set_cycle(1);
    record.set_accepted(true);
    job_.mutable_summary()->add_design(0.2);  // physical: scale 0.1 times 2
    job_.mutable_summary()->add_design_names("r");
  }

  std::string dir_, study_path_;
  v1::GetJobResponse job_;
};

TEST_F(LoadCaseDrawing, TheReportDrawsEveryCaseAtBothDesigns) {
  report::ReportData data;
  AddMechanismDrawings(job_, &data);
  const report::MechanismDrawings& mechanism = data.mechanism;
  EXPECT_EQ(mechanism.note, "");
  EXPECT_FALSE(mechanism.initial.has_value()) << "with cases, only the cases are drawn";
  ASSERT_EQ(mechanism.cases.size(), 2u);
  EXPECT_EQ(mechanism.cases[0].name, "as_built");
  EXPECT_EQ(mechanism.cases[1].name, "long_rod");
  for (const report::LoadCaseDrawings& c : mechanism.cases) EXPECT_EQ(c.note, "") << c.name;
  ExpectSliderCrank(mechanism.cases[0].initial, 0.12, 0.8);
  ExpectSliderCrank(mechanism.cases[0].final, 0.2, 0.8);
  ExpectSliderCrank(mechanism.cases[1].initial, 0.12, 1.0);
  ExpectSliderCrank(mechanism.cases[1].final, 0.2, 1.0);
}

TEST_F(LoadCaseDrawing, DrawWritesOneFigurePerCase) {
  const std::string page = dir_ + "/press_cases.html";
  ASSERT_EQ(DrawCommand({study_path_, "-o", page}), kExitOk);
  std::stringstream html;
  html << std::ifstream(page).rdbuf();
  EXPECT_THAT(html.str(), HasSubstr("<h2>Load case as_built</h2>"));
  EXPECT_THAT(html.str(), HasSubstr("<h2>Load case long_rod</h2>"));
  EXPECT_THAT(html.str(), HasSubstr("id=\"drawing-case-1\""));

  // --case draws that case alone; a name the study lacks is bad input.
  const std::string one = dir_ + "/long_rod.html";
  ASSERT_EQ(DrawCommand({study_path_, "--case", "long_rod", "-o", one}), kExitOk);
  std::stringstream one_html;
  one_html << std::ifstream(one).rdbuf();
  EXPECT_THAT(one_html.str(), HasSubstr("<h2>Load case long_rod</h2>"));
  EXPECT_EQ(one_html.str().find("as_built"), std::string::npos);
  EXPECT_EQ(DrawCommand({study_path_, "--case", "short_rod", "-o", one}), kExitBadInput);
}

// A steel arm clamped horizontal by its driver, bending under its weight
// in the co-rotational formulation (a drive torque output makes its
// analysis elastic).
constexpr char kArm[] = R"pb(
name: "arm"
effects {
  gravity { acceleration_m_per_s2 { x { value: 0 } y { value: -9.81 } } }
  structural_damping { ratio_of_critical: 2 }
}
linkage {
  flexible_formulation: FLEXIBLE_FORMULATION_COROTATIONAL
  joints { name: "O" position_m { x { value: 0 } y { value: 0 } } ground: true }
  joints { name: "T" position_m { x { value: 1 } y { value: 0 } } }
  links {
    name: "arm" joint_a: "O" joint_b: "T" length_m { value: 1 }
    section { area_m2 { value: 1e-3 } youngs_modulus_pa { value: 2e11 } density_kg_per_m3 { value: 7850 } }
    flexible { elements: 4 }
  }
  driver { link: "arm" pivot_joint: "O" start_angle_rad { value: 0 } angular_velocity_rad_per_s { value: 0 } }
}
outputs { name: "torque" drive_torque {} }
time_grid { start_s: 0 end_s: 0.2 points: 3 }
integrator { relative_tolerance: 1e-6 absolute_tolerance: 1e-10 }
)pb";

std::string ReadFile(const std::string& path) {
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  return text.str();
}

TEST(DrawDeflection, TheScaleIsDrawnAndSaid) {
  setenv("MBOPT_WORKER_BIN", MBOPT_TEST_WORKER, 1);
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "draw_deflection";
  std::filesystem::create_directories(dir);
  const std::string scene = (dir / "arm.scene.textproto").string(), page = (dir / "arm.html").string();
  std::ofstream(scene) << kArm;
  ASSERT_EQ(DrawCommand({scene, "-o", page}), kExitOk);
  EXPECT_EQ(ReadFile(page).find("times its size"), std::string::npos);
  ASSERT_EQ(DrawCommand({scene, "-o", page, "--deflection-scale", "1000"}), kExitOk);
  EXPECT_THAT(ReadFile(page), HasSubstr("deflection is drawn 1000 times its size"));
  for (const char* bad : {"0", "-2", "inf", "nan", "big"}) {
    EXPECT_EQ(DrawCommand({scene, "-o", page, "--deflection-scale", bad}), kExitBadInput) << bad;
  }
  // With a position output only, its analysis is kinematic: drawn rigid,
  // and the page says why.
  std::string kinematic = kArm;
  kinematic.replace(kinematic.find("outputs { name: \"torque\" drive_torque {} }"),
                    std::string("outputs { name: \"torque\" drive_torque {} }").size(),
                    "outputs { name: \"tip\" point_position { point: \"T\" axis: AXIS_Y } }");
  std::ofstream(scene, std::ios::trunc) << kinematic;
  ASSERT_EQ(DrawCommand({scene, "-o", page}), kExitOk);
  EXPECT_THAT(ReadFile(page), HasSubstr("the flexible links are drawn rigid, as the analysis moves them"));
}

// The report's section: the arm as a study, its section area a design
// variable; each inner node of the centre line drawn 1000 times as far off
// the straight line between its ends as true to scale.
TEST(DrawDeflection, TheReportMagnifiesTheSameDrawing) {
  setenv("MBOPT_WORKER_BIN", MBOPT_TEST_WORKER, 1);
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "report_deflection";
  std::filesystem::create_directories(dir);
  std::string scene = kArm;
  scene.replace(scene.find("area_m2 { value: 1e-3 }"), std::string("area_m2 { value: 1e-3 }").size(),
                "area_m2 { param: \"A\" }");
  scene += "parameters { name: \"A\" value: 1e-3 unit: \"m^2\" }\n";
  std::ofstream((dir / "arm.scene.textproto").string()) << scene;
  const std::string study_path = (dir / "arm.study.textproto").string();
  std::ofstream(study_path) << R"pb(name: "arm" scene_file: "arm.scene.textproto"
variables { name: "a" parameter: "A" scale: 1e-3 initial: 1 lower: 0.5 upper: 2 }
objective { minimize_max_of: "torque" reduction: REDUCTION_MAX_ABS }
)pb";
  absl::StatusOr<v1::Study> study = spec::io::ReadStudyProto(study_path);
  ASSERT_TRUE(study.ok()) << study.status();
  v1::GetJobResponse job;
  *job.mutable_study() = *study;
  job.add_cycles()->set_cycle(1);
  job.mutable_summary()->add_design(1.2e-3);
  job.mutable_summary()->add_design_names("a");
  report::ReportData plain, magnified;
  AddMechanismDrawings(job, &plain);
  AddMechanismDrawings(job, &magnified, 1000);
  ASSERT_TRUE(plain.mechanism.final.has_value()) << plain.mechanism.note;
  ASSERT_TRUE(magnified.mechanism.final.has_value()) << magnified.mechanism.note;
  const spec::SceneDrawing& p = *plain.mechanism.final;
  const spec::SceneDrawing& m = *magnified.mechanism.final;
  EXPECT_EQ(p.note, "");
  EXPECT_THAT(m.note, HasSubstr("drawn 1000 times its size"));
  ASSERT_EQ(p.lines.size(), 1u);
  const std::vector<int>& line = p.lines[0].points;
  const size_t n = line.size() - 1;
  const spec::DrawingPosition& a = p.points_m.back()[static_cast<size_t>(line.front())];
  const spec::DrawingPosition& b = p.points_m.back()[static_cast<size_t>(line.back())];
  double largest = 0.0;
  for (size_t k = 1; k < n; ++k) {
    const double f = static_cast<double>(k) / n;
    const double cy = a.y_m + (b.y_m - a.y_m) * f;
    const double off = p.points_m.back()[static_cast<size_t>(line[k])].y_m - cy;
    EXPECT_NEAR(m.points_m.back()[static_cast<size_t>(line[k])].y_m - cy, 1000 * off, 1e-9) << "point " << k;
    largest = std::max(largest, std::abs(off));
  }
  EXPECT_GT(largest, 1e-7) << "the arm bends";
}

}  // namespace
}  // namespace mbopt::client
