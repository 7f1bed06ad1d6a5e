// Scenes of the reference problems built directly as spec::Scene objects
// (no file loader), with the data of /benchmarks landing_gear and
// fourbar_stress. Shared by the linkage tests and benchmarks.
#pragma once

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "spec/scene.h"

namespace mbopt::linkage_testing {

inline spec::Number Lit(double v) { return spec::Number{v, -1, nullptr}; }
inline spec::Number Par(int i) { return spec::Number{0.0, i, nullptr}; }
inline spec::Vec2 At(double x, double y) { return {Lit(x), Lit(y)}; }

inline spec::Output PointOutput(std::string name, int link, int point, spec::Axis axis) {
  return {std::move(name), spec::PointPositionOutput{link, point, -1, axis}};
}
inline spec::Output JointOutput(std::string name, int joint, spec::Axis axis) {
  return {std::move(name), spec::PointPositionOutput{-1, -1, joint, axis}};
}

// Landing gear (Hansen 1992 as in benchmarks/landing_gear.md). Parameters
// y1, z1, ..., y4, z4 (m) and theta (rad); joints J1..J4 = 0..3; links bar1
// (J1-J2, driven about J1), coupler (J2-J3, carries P), rocker (J4-J3).
// The driver turns at theta rad/s and the grid is the single instant t = 1 s,
// so the outputs are the end position. Outputs: P_y, P_z, gear rotation.
inline spec::Scene LandingGearScene() {
  spec::Scene s;
  s.name = "landing_gear";
  const char* names[] = {"y1", "z1", "y2", "z2", "y3", "z3", "y4", "z4"};
  for (const char* n : names) s.parameters.push_back({n, 0.0, "mm", 1e-3});
  s.parameters.push_back({"theta", -2.0, "rad", 1.0});
  spec::LinkageModel m;
  for (int k = 0; k < 4; ++k) {
    m.joints.push_back({"J" + std::to_string(k + 1), {Par(2 * k), Par(2 * k + 1)}, k == 0 || k == 3});
  }
  spec::Link bar1;
  bar1.name = "bar1";
  bar1.joint_a = 0;
  bar1.joint_b = 1;
  spec::Link coupler;
  coupler.name = "coupler";
  coupler.joint_a = 1;
  coupler.joint_b = 2;
  coupler.points.push_back({"P", At(0.150, 0.120)});
  spec::Link rocker;
  rocker.name = "rocker";
  rocker.joint_a = 3;
  rocker.joint_b = 2;
  m.links = {bar1, coupler, rocker};
  m.driver.link = 0;
  m.driver.pivot_joint = 0;
  m.driver.angular_velocity_rad_per_s = Par(8);
  s.model = m;
  s.outputs.push_back(PointOutput("P_y", 1, 0, spec::Axis::kX));
  s.outputs.push_back(PointOutput("P_z", 1, 0, spec::Axis::kY));
  s.outputs.push_back({"gear_rotation", spec::LinkRotationOutput{1}});
  s.time_grid = {0.0, 1.0, 1};
  return s;
}

// SI parameter values of a landing-gear design given in mm and rad.
inline std::vector<double> LandingGearDesign(const std::vector<double>& mm_and_theta) {
  std::vector<double> v(mm_and_theta);
  for (int k = 0; k < 8; ++k) v[static_cast<size_t>(k)] *= 1e-3;
  return v;
}

// The stress-constrained four-bar of benchmarks/fourbar_stress.md.
// Parameters A1, A2, A3 (m^2). Joints O2, A, B, O4 = 0..3; links crank
// (O2->A), coupler (A->B), rocker (O4->B). `elements` > 0 makes the links
// flexible. Outputs: stress_crank, stress_coupler, stress_rocker, mass,
// drive_torque; grid 0.3..0.5 s, 101 instants.
struct FourBarOptions {
  int elements = 0;
  double youngs_modulus_pa = 6.895e10;
  bool rotary_inertia = false;
  bool damping = false;
  double damping_ratio = 0.05;
};
constexpr double kFourBarAllowablePa = 2.758e7;
constexpr double kCrankM = 0.3048, kCouplerM = 0.9144, kRockerM = 0.762, kGroundM = 0.9144;

inline spec::Scene FourBarScene(const FourBarOptions& o = {}) {
  spec::Scene s;
  s.name = "fourbar";
  s.parameters = {{"A1", 0.1, "", 1.0}, {"A2", 0.1, "", 1.0}, {"A3", 0.1, "", 1.0}};
  if (o.damping) s.effects.structural_damping_ratio = o.damping_ratio;
  spec::LinkageModel m;
  m.joints = {{"O2", At(0, 0), true},
              {"A", At(0, -kCrankM), false},
              {"B", At(0.37, 0.53), false},  // initial guess, above the ground line
              {"O4", At(kGroundM, 0), true}};
  auto link = [&](std::string name, int a, int b, double len, int area) {
    spec::Link l;
    l.name = std::move(name);
    l.joint_a = a;
    l.joint_b = b;
    l.length_m = Lit(len);
    l.section = spec::Section{Par(area), Lit(o.youngs_modulus_pa), Lit(2757.0)};
    l.flexible_elements = o.elements;
    l.rotary_inertia = o.rotary_inertia;
    return l;
  };
  m.links = {link("crank", 0, 1, kCrankM, 0), link("coupler", 1, 2, kCouplerM, 1),
             link("rocker", 3, 2, kRockerM, 2)};
  m.driver.link = 0;
  m.driver.pivot_joint = 0;
  m.driver.start_angle_rad = Lit(-std::numbers::pi / 2);
  m.driver.angular_velocity_rad_per_s = Lit(10 * std::numbers::pi);
  s.model = m;
  s.outputs = {{"stress_crank", spec::BendingStressOutput{0}},
               {"stress_coupler", spec::BendingStressOutput{1}},
               {"stress_rocker", spec::BendingStressOutput{2}},
               {"mass", spec::MassOutput{}},
               {"drive_torque", spec::DriveTorqueOutput{}}};
  s.time_grid = {0.3, 0.5, 101};
  return s;
}

}  // namespace mbopt::linkage_testing
