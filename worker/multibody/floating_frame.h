// The floating-frame formulation of flexible links (the kineto-elastodynamic
// model): the moving links of a driven linkage as planar Euler-Bernoulli
// beams (floating_frame_beam.h) whose small elastic deformation rides on the
// large rigid motion the multibody kinematic analysis gives at any t
// (RigidMotionAt). The cheap effect level: the co-rotational links of the
// multibody engine (flexible_link.h) are the accurate one, at many times
// the cost (docs/accuracy.md).
//
// Unknowns: elastic nodal displacements in the global frame. The two joints
// of a pin share their elastic translations; each link keeps its own end
// rotations; ground joints have none; the driven link's root rotation is
// clamped to the driver. Each element's matrices follow its link's rigid
// orientation, so M(t) and K(t) change with the motion:
//   M(t) u'' + C(t) u' + (K(t) + K_G(u, t)) u = M(t) (g - a_rigid(t)),
// K_G: geometric stiffness of each element's own axial force (the P-delta
// effect, first order in N / P_euler); C = beta K, beta = 2 zeta / omega_1
// (omega_1: the lowest bending frequency over the links, each with its ends
// pinned, the driven root clamped), only if the scene declares structural
// damping. Terms of second order in the frame rotation (Coriolis,
// centrifugal softening of the elastic displacements) are neglected; their
// relative size is (crank speed / lowest link frequency)^2.
// Integrated with CVODES BDF from the undeformed state (elastic velocities
// zero: the links start with their rigid-body velocities). Each Newton
// system is solved through the second-order structure, a Cholesky
// factorization of M + gamma C + gamma^2 K at the step's own t and gamma (the
// matrices rotate with the links, so a reused Jacobian would not converge).
//
// Bending moments at the nodes are recovered from the element end forces
// ((K + K_G) d + C d' + M (a - g) in the element frame, the moment a node
// transmits), averaged between the two elements that meet at an inner node.
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Dense>

#include "spec/analysis_outcome.h"
#include "spec/scene.h"
#include "worker/budget/analysis_budget.h"
#include "worker/multibody/linkage_system.h"
#include "worker/sundials/cvodes_integrator.h"

namespace mbopt::multibody {

// The rigid reference motion at t (any t the integrator asks for).
using RigidMotionAt = std::function<spec::AnalysisFailure(double t_s, LinkageState* state)>;

struct FloatingFrameResult {
  std::vector<LinkageState> rigid_states;  // [instant]: the rigid reference motion
  // [instant][link][node] bending moment, N m (the rigid bars' sign
  // convention, linkage_front_end.h).
  std::vector<std::vector<std::vector<double>>> node_moment_n_m;
  std::vector<double> drive_torque_n_m;  // [instant]
  sundials::CvodesCounters counters;
  double lowest_link_frequency_rad_per_s = 0.0;
  // [instant][link][node] elastic displacement of every node of a moving
  // link, world axes, m: its nodes from joint a to joint b (elements + 1;
  // none for a link with both ends on the ground). Kept only when
  // RunFloatingFrame is asked to (a drawing of the deflected links); an
  // analysis leaves it empty.
  std::vector<std::vector<std::vector<Eigen::Vector2d>>> node_displacement_m;
};

// Fails (with a reason naming the time, or the rigid link) if a moving link
// is rigid, the rigid motion fails, or the integrator gives up.
spec::AnalysisFailure RunFloatingFrame(const LinkageSystem& system, const spec::IntegratorSettings& integrator,
                                       const std::vector<double>& times_s, const RigidMotionAt& rigid_motion,
                                       const budget::AnalysisBudget* budget, FloatingFrameResult* result,
                                       bool keep_node_displacements = false);

}  // namespace mbopt::multibody
