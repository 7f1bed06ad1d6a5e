// The force elements of a spatial Model beyond gravity and translational
// springs: point forces and torques (constant or times a time factor),
// rotational spring-dampers on revolute and cylindrical joints, and
// bushings. Their generalized forces on the Euler-parameter coordinates of
// SpatialSystem, their potential energy, and the values outputs read.
//
// A bushing between frames a and b measures, in frame a's axes,
//   u = A_a^T (o_b - o_a)                  (m: the displacement of b's origin)
//   theta = vec(skew(A_a^T A_b))           (rad: the small-angle rotation)
// with A_a, A_b the frames' axes in world axes and vec(skew(R)) the axial
// vector of (R - R^T) / 2: theta_x = (a_z.b_y - a_y.b_z) / 2 and cyclic,
// which is sin(angle) * axis for a rotation by `angle` about `axis`. Its
// potential (u^T K u + theta^T Kr theta) / 2 and the dampings' rates
// du/dt, dtheta/dt give the generalized forces -(du/dq)^T (K u + C du/dt)
// - (dtheta/dq)^T (Kr theta + Cr dtheta/dt): they depend only on the
// relative pose, so they conserve momentum, and the stiffness part does no
// work around a closed path. The force on body b, at b's origin, is
// exactly -(K u + C du/dt) in a's axes; the moment is -(Kr theta + Cr
// dtheta/dt) to first order in the rotation (docs/physics.md, "Spatial
// force elements").
#pragma once

#include <string>

#include <Eigen/Dense>

#include "absl/status/status.h"
#include "worker/spatial/spatial_model.h"

namespace mbopt::spatial {

// InvalidArgument naming the element and what was expected.
absl::Status ValidateForceElements(const Model& model);

// Adds the elements' generalized forces at (t, q, v) to `forces` (7 per
// body, SpatialSystem's layout). 0, or 1 when a value is not finite.
int AddForceElementForces(const Model& model, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                          Eigen::VectorXd* forces);

// The rotational springs' and bushings' strain energy (J).
double ForceElementPotentialEnergy(const Model& model, const Eigen::VectorXd& q);

// The torque rotational spring `spring` applies to its joint's body b about
// the joint axis (N m).
double RotationalSpringTorque(const Model& model, int spring, const Eigen::VectorXd& q, const Eigen::VectorXd& v);

// A bushing's force (N) and moment (N m) on body b, in frame a's axes.
struct BushingLoad {
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment_n_m = Eigen::Vector3d::Zero();
};
BushingLoad BushingLoadOf(const Model& model, int bushing, const Eigen::VectorXd& q, const Eigen::VectorXd& v);

// A spring's tension (N) at length L and rate dL/dt: its curves where it
// has them, else its coefficients, plus the actuator force. A curve's
// argument outside its table gives NaN, unless `continued` (an
// integrator's trial step across the table's end, see
// multibody::ConstrainedSystem::ContinuePastBounds): then the end
// segment's line.
double SpringTension(const SpringDamper& s, double length_m, double rate_m_per_s, bool continued);

// A spring's strain energy (J): the integral of its elastic force over the
// deflection from 0 (the curve continued along its end segments), plus the
// actuator force times the length.
double SpringStrainEnergy(const SpringDamper& s, double length_m);

// The springs' force curves' tables as validity bounds
// (multibody::ConstrainedSystem::ValidityBounds): two per curve, in spring
// order, deflection curve before velocity curve, lower end before upper.
int SpringCurveBoundCount(const Model& model);
void SpringCurveBounds(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& v, double* g);
std::string SpringCurveBoundReason(const Model& model, int bound, double t, const Eigen::VectorXd& q,
                                   const Eigen::VectorXd& v);

}  // namespace mbopt::spatial
