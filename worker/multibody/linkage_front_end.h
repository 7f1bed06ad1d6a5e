// The linkage front end of the multibody engine: a resolved linkage scene
// (linkage_system.h) compiled into a multibody Model, and the engine's
// results read back in the linkage's terms.
//
// The compiled model: one body per moving bar (both pins on the ground: no
// body, it carries nothing), its centre at the bar's middle, its x axis
// along the bar from joint a to joint b, mass rho A L and inertia
// rho A L^3 / 12 (+ rho I L with rotary inertia) about the centre; a bar
// without a section is massless (the model is then not one Model::Validate
// accepts, but a kinematic analysis and its inverse dynamics invert no mass
// matrix). A pin joining k moving bars is k - 1 revolute joints from the
// first bar's end to each other's; a ground pin is one revolute joint from a
// ground point to each bar pinned there. The driver is a constant-rate
// driver of the revolute joint between the ground and the driven bar at its
// pivot (the joint coordinate is the bar's absolute angle). Every revolute
// joint is named after its pin, so the engine's messages name the pin.
#pragma once

#include <vector>

#include "worker/multibody/linkage_system.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/model.h"
#include "worker/multibody/motion.h"

namespace mbopt::multibody {

struct CompiledLinkage {
  Model model;
  // Per link: its body, or -1 for a bar with both pins on the ground.
  std::vector<int> link_body;
  // Per linkage joint: a point of the model at the pin (an end of a moving
  // bar pinned there, or the ground point).
  std::vector<Point> joint_point;
  // Per model joint: the links and ends (0: joint a, 1: joint b) its points a
  // and b are; link -1 for the ground.
  struct PinEnds {
    int link_a = -1, end_a = 0, link_b = -1, end_b = 0;
  };
  std::vector<PinEnds> pin_ends;
  // Co-rotational links only: per link, its first node body (end a) and
  // its first element in Model::beams; -1 for a bar with both pins on the
  // ground.
  std::vector<int> link_first_node, link_first_element;
};

CompiledLinkage CompileLinkage(const LinkageSystem& system);

// The same linkage with every moving link a co-rotational flexible link
// (flexible_link.h) of its `flexible_elements` elements: EA, EI = E A^2 /
// (4 pi), rho A lumped at the nodes (+ rho I with rotary inertia); the pins
// join the end nodes, the driver turns the driven link's root node (its
// root clamped to the driver, as in the floating frame). Structural damping
// C = beta K, beta = 2 zeta / omega_1, omega_1 the lowest first bending
// frequency over the links alone, ends pinned or the driven root clamped
// (closed form, as the multibody scenes' flexible links). Every moving link
// must be flexible.
CompiledLinkage CompileCorotationalLinkage(const LinkageSystem& system);

// The number of unknowns (2 per moving pin) minus the equations (one length
// per bar, two for the driven bar's end) of the driven linkage: it must be 0.
// `message` says why not.
int LinkageDegreesOfFreedom(const LinkageSystem& system, std::string* message);

// The sample's motion per linkage joint.
void ToLinkageState(const Mechanism& mechanism, const CompiledLinkage& compiled, const MotionSample& sample,
                    LinkageState* state);

// Bending moment stations of a link: its beam elements + 1, or 7 for a
// rigid link (the report's 6 elements per link).
int StressNodes(const LinkageLink& link);

// The bending moments of the rigid bars at their stations and the drive
// torque, from the inverse dynamics of `sample` (its multipliers): each
// bar's pin force at joint a (the revolute joints' reactions on it) and the
// driver's effort, with the bar's own load along it, rho A (g - a(s)) per
// length, a(s) linear between the joint accelerations, and the distributed
// moment -rho I alpha with rotary inertia. The moment at station s is the
// moment about it of the loads on the part s' > s (counter-clockwise
// positive, EI w'' with w along the bar's left normal).
struct RigidBarLoads {
  double drive_torque_n_m = 0.0;  // on the driven bar, counter-clockwise positive
  std::vector<std::vector<double>> node_moment_n_m;  // [link][station]
};
void RigidBarMoments(const LinkageSystem& system, const Mechanism& mechanism, const CompiledLinkage& compiled,
                     const MotionSample& sample, const LinkageState& state, RigidBarLoads* loads);

}  // namespace mbopt::multibody
