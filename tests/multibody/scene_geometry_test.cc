// The drawing geometry of multibody and linkage scenes
// (worker/multibody/scene_geometry.h, linkage_geometry.h) against
// closed-form positions, and against the analysis' own numbers; a scene
// drawn on the explicit path as on IDAS.
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "tests/multibody/andrews_on_both_paths.h"
#include "tests/testing/drawing_agreement.h"
#include "worker/multibody/kinematic_analysis.h"
#include "worker/multibody/linkage_geometry.h"
#include "worker/multibody/scene_analysis.h"
#include "worker/multibody/scene_geometry.h"

namespace mbopt::multibody {
namespace {

// Positions are closed by Newton to 1e-11 m (AssemblyOptions); a few
// times that covers round-off of coordinates of order 1 m.
constexpr double kPositionTolerance = 1e-9;

spec::Scene Load(const std::string& path) {
  absl::StatusOr<spec::Scene> scene = spec::io::LoadSceneFile(path);
  EXPECT_TRUE(scene.ok()) << scene.status();
  return *scene;
}

int PointNamed(const spec::SceneDrawing& d, const std::string& name) {
  for (size_t k = 0; k < d.point_names.size(); ++k) {
    if (d.point_names[k] == name) return static_cast<int>(k);
  }
  ADD_FAILURE() << "no point named " << name;
  return 0;
}

// The press (examples/press): a slider crank with crank radius r, rod l,
// the crank turning at pi rad/s from 0. Closed form: crank pin
// r (cos th, sin th), slider at x = r cos th + sqrt(l^2 - r^2 sin^2 th),
// y = 0, on a slider joint whose axis is the x axis.
TEST(MultibodyDrawing, PressFollowsTheSliderCrankClosedForm) {
  const spec::Scene scene = Load("examples/press/press.scene.textproto");
  const std::vector<double> p = scene.DefaultParameterValues();
  const double r = 0.15, l = 0.8;
  const spec::SceneDrawing d = DrawMultibodyScene(scene, p);
  ASSERT_EQ(d.failure, "");
  ASSERT_EQ(d.times_s.size(), 101u);
  ASSERT_EQ(d.points_m.size(), 101u);
  const int pin = PointNamed(d, "crank.pin"), slider = PointNamed(d, "slider.pin"), main = PointNamed(d, "main");
  for (size_t i = 0; i < d.times_s.size(); ++i) {
    const double th = std::numbers::pi * d.times_s[i];
    const auto& at = d.points_m[i];
    EXPECT_NEAR(at[pin].x_m, r * std::cos(th), kPositionTolerance) << "t = " << d.times_s[i];
    EXPECT_NEAR(at[pin].y_m, r * std::sin(th), kPositionTolerance);
    EXPECT_NEAR(at[slider].x_m, r * std::cos(th) + std::sqrt(l * l - r * r * std::sin(th) * std::sin(th)),
                kPositionTolerance);
    EXPECT_NEAR(at[slider].y_m, 0.0, kPositionTolerance);
    EXPECT_EQ(at[main].x_m, 0.0);  // ground stays put
  }
  EXPECT_THAT(d.ground_points, ::testing::Contains(main));
  int sliders = 0;
  for (const spec::SceneDrawing::Joint& j : d.joints) {
    if (j.kind != spec::SceneDrawing::JointKind::kSlider) continue;
    ++sliders;
    EXPECT_EQ(j.name, "guide");
    EXPECT_EQ(j.point, slider);
    ASSERT_EQ(j.axis_angle_rad.size(), d.times_s.size());
    for (const double angle : j.axis_angle_rad) EXPECT_EQ(angle, 0.0);  // along x, fixed in ground
  }
  EXPECT_EQ(sliders, 1);
  // The crank and the rod are drawn between their two markers; the slider
  // around its one marker (at its centre of mass, so no second point).
  ASSERT_EQ(d.bodies.size(), 3u);
  EXPECT_THAT(d.bodies[0].points, ::testing::ElementsAre(PointNamed(d, "crank.pivot"), pin));
  EXPECT_THAT(d.bodies[1].points, ::testing::ElementsAre(PointNamed(d, "rod.big_end"), PointNamed(d, "rod.small_end")));
  EXPECT_THAT(d.bodies[2].points, ::testing::ElementsAre(slider));
}

// The drawing follows the motion the analysis computes: the slider's x at
// every instant is the analysis' output slider_x, bit for bit (the same
// model, assembly and kinematics).
TEST(MultibodyDrawing, ReproducesTheAnalysisNumbers) {
  const spec::Scene scene = Load("examples/press/press.scene.textproto");
  const std::vector<double> p = scene.DefaultParameterValues();
  const spec::AnalysisReport report = AnalyzeMultibodyScene(scene, p);
  ASSERT_TRUE(report.ok()) << report.failure.reason;
  const spec::SceneDrawing d = DrawMultibodyScene(scene, p);
  const int slider = PointNamed(d, "slider.pin");
  const int output = scene.FindOutput("slider_x");
  ASSERT_GE(output, 0);
  ASSERT_EQ(d.times_s, report.times_s);
  for (size_t i = 0; i < d.times_s.size(); ++i) {
    EXPECT_EQ(d.points_m[i][slider].x_m, report.outputs[static_cast<size_t>(output)].series[0][i]);
  }
}

// An analysis does no work for a drawing: its position solves and Newton
// iterations are those of the kinematic analysis alone on the same grid.
TEST(MultibodyDrawing, AnalysisWithoutDrawingDoesNoExtraWork) {
  spec::Scene scene = Load("examples/press/press.scene.textproto");
  // Positions only: no inverse dynamics, so the work is the motion's.
  scene.outputs.erase(scene.outputs.begin());  // the driver's effort
  const std::vector<double> p = scene.DefaultParameterValues();
  const spec::AnalysisReport report = AnalyzeMultibodyScene(scene, p);
  ASSERT_TRUE(report.ok()) << report.failure.reason;

  absl::StatusOr<Model> model = CompileModel(scene, p);
  ASSERT_TRUE(model.ok());
  const Mechanism mechanism(*model);
  const Assembly assembled = Assemble(mechanism, 0.0);
  ASSERT_TRUE(assembled.failure.ok());
  KinematicCounters counters;
  const spec::AnalysisFailure outcome = RunKinematics(
      mechanism, assembled.q, scene.time_grid.Instants(), KinematicOptions{},
      [](const MotionSample&) { return spec::AnalysisFailure::Ok(); }, &counters);
  ASSERT_TRUE(outcome.ok());
  EXPECT_EQ(report.counters.position_solves, counters.position_solves);
  EXPECT_EQ(report.counters.newton_iterations, counters.newton_iterations + assembled.newton_iterations);
}

// A flexible link pinned to the ground at one end, no load, no gravity:
// at rest, its centre line stays straight along its angle with its nodes
// evenly spaced.
TEST(MultibodyDrawing, FlexibleLinkAtRestIsStraight) {
  absl::StatusOr<spec::Scene> scene = spec::io::ParseSceneText(R"pb(
    name: "beam_at_rest"
    multibody {
      ground_markers { name: "root" position_m { x { value: 0.1 } y { value: 0.2 } } }
      flexible_links {
        name: "beam"
        start_m { x { value: 0.1 } y { value: 0.2 } }
        angle_rad { value: 0.5 }
        length_m { value: 1.2 }
        section { area_m2 { value: 1e-4 } youngs_modulus_pa { value: 2e11 } density_kg_per_m3 { value: 7800 } }
        elements: 6
      }
      joints { name: "root" kind: JOINT_REVOLUTE a: "ground.root" b: "beam.a" }
    }
    outputs { name: "tip_y" marker_position { marker: "beam.b" axis: AXIS_Y } }
    time_grid { start_s: 0 end_s: 0.1 points: 5 }
  )pb",
                                                                 "beam_at_rest.scene.textproto");
  ASSERT_TRUE(scene.ok()) << scene.status();
  const spec::SceneDrawing d = DrawMultibodyScene(*scene, scene->DefaultParameterValues());
  ASSERT_EQ(d.failure, "");
  ASSERT_EQ(d.lines.size(), 1u);
  const std::vector<int>& nodes = d.lines[0].points;
  ASSERT_EQ(nodes.size(), 7u);
  ASSERT_EQ(d.points_m.size(), 5u);
  for (const auto& at : d.points_m) {
    for (size_t k = 0; k < nodes.size(); ++k) {
      const double s = 1.2 * static_cast<double>(k) / 6.0;
      EXPECT_NEAR(at[nodes[k]].x_m, 0.1 + s * std::cos(0.5), kPositionTolerance) << "node " << k;
      EXPECT_NEAR(at[nodes[k]].y_m, 0.2 + s * std::sin(0.5), kPositionTolerance) << "node " << k;
    }
  }
}

// The four-bar of examples/fourbar: at every instant the crank's end is
// where the driver's angle puts it, and the coupler and rocker keep their
// lengths (the loop closes); ground pins do not move.
TEST(LinkageDrawing, FourBarClosesItsLoopAtEveryInstant) {
  const spec::Scene scene = Load("examples/fourbar/fourbar_rigid.scene.textproto");
  const spec::SceneDrawing d = DrawLinkageScene(scene, scene.DefaultParameterValues());
  ASSERT_EQ(d.failure, "");
  ASSERT_EQ(d.times_s.size(), 101u);
  const int o2 = PointNamed(d, "O2"), a = PointNamed(d, "A"), b = PointNamed(d, "B"), o4 = PointNamed(d, "O4");
  EXPECT_THAT(d.ground_points, ::testing::UnorderedElementsAre(o2, o4));
  ASSERT_EQ(d.bodies.size(), 3u);
  const double omega = 31.41592653589793, start = -std::numbers::pi / 2;
  for (size_t i = 0; i < d.times_s.size(); ++i) {
    const auto& at = d.points_m[i];
    const double th = start + omega * d.times_s[i];
    EXPECT_NEAR(at[a].x_m, 0.3048 * std::cos(th), kPositionTolerance) << "t = " << d.times_s[i];
    EXPECT_NEAR(at[a].y_m, 0.3048 * std::sin(th), kPositionTolerance);
    EXPECT_NEAR(std::hypot(at[b].x_m - at[a].x_m, at[b].y_m - at[a].y_m), 0.9144, kPositionTolerance);
    EXPECT_NEAR(std::hypot(at[b].x_m - at[o4].x_m, at[b].y_m - at[o4].y_m), 0.762, kPositionTolerance);
    EXPECT_EQ(at[o4].x_m, 0.9144);
    EXPECT_EQ(at[o4].y_m, 0.0);
  }
}

// The same four-bar at t = 0 with the driver at -90 degrees: the crank end
// A straight below O2, and B at the intersection of the circles about A
// (radius 0.9144) and O4 (radius 0.762) on the side of its initial guess
// (above the ground line).
TEST(LinkageDrawing, FourBarStartsWhereClosedFormGeometryPutsIt) {
  spec::Scene scene = Load("examples/fourbar/fourbar_rigid.scene.textproto");
  scene.time_grid = spec::TimeGrid{0.0, 0.0, 1};
  const spec::SceneDrawing d = DrawLinkageScene(scene, scene.DefaultParameterValues());
  ASSERT_EQ(d.failure, "");
  ASSERT_EQ(d.points_m.size(), 1u);
  const auto& at = d.points_m[0];
  const double ax = 0.0, ay = -0.3048, ox = 0.9144, oy = 0.0, r1 = 0.9144, r2 = 0.762;
  const double dist = std::hypot(ox - ax, oy - ay);
  const double along = (r1 * r1 - r2 * r2 + dist * dist) / (2 * dist);
  const double across = std::sqrt(r1 * r1 - along * along);
  const double ux = (ox - ax) / dist, uy = (oy - ay) / dist;
  // The left normal of A -> O4 points up and to the left: B's guess side.
  const double bx = ax + along * ux - across * uy, by = ay + along * uy + across * ux;
  const int a = PointNamed(d, "A"), b = PointNamed(d, "B");
  EXPECT_NEAR(at[a].x_m, ax, kPositionTolerance);
  EXPECT_NEAR(at[a].y_m, ay, kPositionTolerance);
  EXPECT_NEAR(at[b].x_m, bx, kPositionTolerance);
  EXPECT_NEAR(at[b].y_m, by, kPositionTolerance);
}

TEST(MultibodyDrawing, AnUnassembledSceneIsDrawnAsGivenWithTheReason) {
  spec::Scene scene = Load("examples/press/press.scene.textproto");
  auto& model = std::get<spec::MultibodyModel>(scene.model);
  // The rod cannot reach: the slider on its guide farther than r + l.
  spec::Number far;
  far.value = 5.0;
  model.ground_markers[1].position_m.y = far;
  const spec::SceneDrawing d = DrawMultibodyScene(scene, scene.DefaultParameterValues());
  EXPECT_THAT(d.failure, ::testing::HasSubstr("does not assemble"));
  EXPECT_EQ(d.points_m.size(), 1u);
}

// Andrews' squeezing mechanism (examples/andrews) drawn with
// `integrator { method: EXPLICIT_RUNGE_KUTTA }` has the frames of its
// drawing on the default path (IDAS): the same instants and points, every
// point where IDAS puts it to the paths' integration error; the explicit
// path must have run (its round-off is not IDAS's) and the mechanism moved.
TEST(MultibodyDrawing, TheExplicitPathDrawsTheFramesOfTheDefaultPath) {
  const std::optional<testing::ScenesOnBothPaths> scenes = testing::AndrewsOnBothPaths();
  ASSERT_TRUE(scenes.has_value());
  const spec::SceneDrawing idas = DrawMultibodyScene(scenes->idas, scenes->idas.DefaultParameterValues());
  const spec::SceneDrawing erk =
      DrawMultibodyScene(scenes->explicit_path, scenes->explicit_path.DefaultParameterValues());
  ASSERT_EQ(idas.failure, "");
  ASSERT_EQ(erk.failure, "");
  ASSERT_EQ(idas.times_s.size(), 31u);
  // Both paths at rtol 1e-8 over 0.03 s, links of a few centimetres: the
  // positions differ by 2.1e-9 m at most (measured); the points move up to
  // 14 mm.
  constexpr double kPathAgreement = 2e-8;  // m
  mbopt::testing::ExpectTheFramesOfTheDefaultPath(idas, erk, kPathAgreement, 0.005, "Andrews' mechanism");
}

}  // namespace
}  // namespace mbopt::multibody

namespace mbopt::multibody {
namespace {

// Loads are drawn where they act and which way: the press's 5000 N along +x
// at the slider's pin.
TEST(MultibodyDrawing, PointForceIsALoadAtItsMarkerAlongTheForce) {
  const spec::Scene scene = Load("examples/press/press.scene.textproto");
  const spec::SceneDrawing d = DrawMultibodyScene(scene, scene.DefaultParameterValues());
  ASSERT_EQ(d.failure, "");
  ASSERT_EQ(d.loads.size(), 1u);
  EXPECT_EQ(d.loads[0].kind, spec::SceneDrawing::LoadKind::kForce);
  EXPECT_EQ(d.loads[0].point, PointNamed(d, "slider.pin"));
  EXPECT_EQ(d.loads[0].direction_x, 1.0);
  EXPECT_EQ(d.loads[0].direction_y, 0.0);
  for (const spec::SceneDrawing::Joint& j : d.joints) {
    EXPECT_FALSE(j.rotational_spring || j.rotational_damper) << j.name << ": the press has no rotational spring";
  }
}

// A rotational spring-damper is drawn at its pin, a body torque at the
// body's centre of mass, which joins no outline, with its sense.
TEST(MultibodyDrawing, RotationalSpringMarksItsPinAndATorqueItsBody) {
  absl::StatusOr<spec::Scene> scene = spec::io::ParseSceneText(R"pb(
name: "arm"
multibody {
  bodies {
    name: "arm"
    mass_kg { value: 2 }
    inertia_kg_m2 { value: 0.1 }
    position_m { x { value: 0.4 } }
    markers { name: "pin" position_m { x { value: -0.4 } } }
    markers { name: "tip" position_m { x { value: 0.4 } } }
  }
  joints { name: "pin" kind: JOINT_REVOLUTE a: "ground.origin" b: "arm.pin" }
  ground_markers { name: "origin" }
  rotational_springs { name: "spring" joint: "pin" stiffness_n_m_per_rad { value: 20 } damping_n_m_s_per_rad { value: 0.5 } }
  torques { body: "arm" torque_n_m { value: -3 } }
}
outputs { name: "angle" joint_coordinate { joint: "pin" } }
time_grid { start_s: 0 end_s: 0.1 points: 3 }
)pb",
                                                                   "arm.scene.textproto");
  ASSERT_TRUE(scene.ok()) << scene.status();
  const spec::SceneDrawing d = DrawMultibodyScene(*scene, scene->DefaultParameterValues());
  ASSERT_EQ(d.failure, "");
  ASSERT_EQ(d.joints.size(), 1u);
  EXPECT_TRUE(d.joints[0].rotational_spring);
  EXPECT_TRUE(d.joints[0].rotational_damper);
  ASSERT_EQ(d.loads.size(), 1u);
  const spec::SceneDrawing::Load& torque = d.loads[0];
  EXPECT_EQ(torque.kind, spec::SceneDrawing::LoadKind::kTorque);
  EXPECT_EQ(torque.direction_x, -1.0) << "clockwise";
  EXPECT_NEAR(d.points_m[0][static_cast<size_t>(torque.point)].x_m, 0.4, kPositionTolerance);
  ASSERT_EQ(d.bodies.size(), 1u);
  EXPECT_THAT(d.bodies[0].points, ::testing::Not(::testing::Contains(torque.point)));
}

}  // namespace
}  // namespace mbopt::multibody
