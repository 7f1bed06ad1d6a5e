// Analysis of a linkage scene (spec::LinkageModel) at one design point on
// the multibody engine: the scene resolved (linkage_system.h), compiled to a
// Model (linkage_front_end.h), assembled at t = 0 and followed by the
// kinematic analysis. Picks the cheapest formulation the requested outputs
// allow:
//  - kinematic: only positions and rotations requested;
//  - kinetostatic: forces, stresses or drive torque of rigid links (inverse
//    dynamics; the bending moment along each rigid bar from its pin forces
//    and its acceleration field);
//  - elastodynamic: the same for a linkage with flexible links, in the
//    floating-frame formulation (floating_frame.h) on the kinematic motion.
// A mechanism that cannot assemble, locks or changes branch, and an
// integrator failure, give status kFailed with a reason naming the time and
// the joint or link; never a number. Pure: no I/O, no threads.
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "spec/analysis_report.h"
#include "spec/scene.h"
#include "worker/budget/analysis_budget.h"
#include "worker/multibody/linkage_system.h"

namespace mbopt::multibody {

// An elastic analysis' own motion, for a drawing of the deflected links
// (linkage_geometry.h), at each grid instant solved (those before a
// failure). The floating frame: the rigid reference motion and every moving
// link's elastic node displacements (FloatingFrameResult). The
// co-rotational formulation: the coordinates of the model
// CompileCorotationalLinkage builds (every node body's x, y, phi).
struct LinkageDeflection {
  std::vector<LinkageState> rigid_states;                                      // [instant], floating frame
  std::vector<std::vector<std::vector<Eigen::Vector2d>>> node_displacement_m;  // [instant][link][node], world, m
  std::vector<Eigen::VectorXd> corotational_q;                                 // [instant], co-rotational
};

// `scene.model` must hold a LinkageModel; `parameter_values_si` has one SI
// value per scene parameter. `budget` (none: no limit) bounds the kinematic
// sweep, the integration and every position solve. `deflection`, when
// given, receives the motion of an elastic analysis (left empty by the
// kinematic and kinetostatic ones); without it nothing is kept for a
// drawing.
spec::AnalysisReport AnalyzeLinkageScene(const spec::Scene& scene, const std::vector<double>& parameter_values_si,
                                         budget::AnalysisBudget* budget = nullptr,
                                         LinkageDeflection* deflection = nullptr);

// Whether AnalyzeLinkageScene follows `sys`'s links elastically in the
// floating-frame formulation: a link is flexible, an output needs loads
// (bending stress, drive torque), and the scene asks for no co-rotational
// formulation.
bool UsesFloatingFrame(const spec::Scene& scene, const LinkageSystem& sys);

// Whether it follows them in the co-rotational formulation: a link is
// flexible, an output needs loads, and the scene asks for that formulation.
bool UsesCorotational(const spec::Scene& scene, const LinkageSystem& sys);

// Whether an output of the scene needs loads (bending stress, drive
// torque): without one a linkage's analysis is kinematic, its flexible
// links followed rigidly (docs/physics.md, the cheapest formulation).
bool NeedsLoads(const spec::Scene& scene);

}  // namespace mbopt::multibody
