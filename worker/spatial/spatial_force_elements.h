// The force elements of a spatial Model beyond gravity and translational
// springs: point forces and torques (constant or times a time factor),
// rotational spring-dampers on revolute and cylindrical joints, and
// bushings. Their generalized forces on the Euler-parameter coordinates of
// SpatialSystem, their potential energy, and the values outputs read.
//
// A bushing between frames a and b measures, in frame a's axes,
//   u = A_a^T (o_b - o_a)            (m: the displacement of b's origin)
//   theta = (theta_x, theta_y, theta_z)  (rad: b's x-y-z body-fixed angles
//                                         in a, R = A_a^T A_b
//                                         = Rx(theta_x) Ry(theta_y) Rz(theta_z))
// with A_a, A_b the frames' axes in world axes: the measure of Simbody's
// Force::LinearBushing, valid for large rotations while the middle angle
// theta_y stays away from +-90 deg, where the angles are singular. Its
// potential (u^T K u + theta^T Kr theta) / 2 and the dampings on the
// rates du/dt, dtheta/dt give the generalized forces
//   -(du/dq)^T (K u + C du/dt) - (dtheta/dq)^T (Kr theta + Cr dtheta/dt):
// the exact gradient of the potential, so an undamped bushing conserves
// energy; they depend only on the relative pose, so they conserve
// momentum. The force on body b, at b's origin, is -(K u + C du/dt) in
// a's axes; the couple on b is the moment whose power equals that of the
// angles' generalized forces (docs/physics.md section 8, "Force elements"
// and "Why x-y-z angles for the bushing").
// Past kBushingMiddleAngleLimit_rad the analysis ends naming the bushing
// (a validity bound; an evaluation outside a continued scope fails).
//
// A rotational spring's angle is continuous along a motion: the joint's
// angle atan2 in (-pi, pi] plus the whole turns counted against the angle
// of the latest evaluation (SpringAngles), so a spring wound several turns
// keeps k (theta - theta0) for any theta - theta0.
#pragma once

#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "absl/status/status.h"
#include "worker/spatial/spatial_model.h"

namespace mbopt::spatial {

// InvalidArgument naming the element and what was expected.
absl::Status ValidateForceElements(const Model& model);

// The rotational springs' joint angles as continuous functions of the
// motion. The state holds absolute orientations, from which a joint's
// angle is only known modulo a turn; each evaluation takes the value
// angle + 2 pi n nearest the angle this object returned last for that
// spring (0 before the first, so the first is in (-pi, pi]), and
// remembers it. Between two evaluations a joint must turn by less than
// half a turn: integrator steps, their Newton iterates and difference
// quotients, and an analysis' consecutive instants, all do by far (a step
// turning a joint by pi would not resolve its motion). The value is
// principal + 2 pi n with n an integer, so within a step (n fixed) it is a
// smooth function of the state, and a rerun, evaluating the same states in
// the same order, gives the same bits.
class SpringAngles {
 public:
  explicit SpringAngles(size_t springs) : latest_rad_(springs, 0.0) {}
  double Follow(int spring, double principal_rad);

 private:
  std::vector<double> latest_rad_;
};

// A bushing's middle angle (theta_y) must stay within this of zero: the
// angles' rates, and so the moments of the dampings, carry 1 / cos(theta_y),
// 11.5 here, and are undefined at 90 deg.
inline constexpr double kBushingMiddleAngleLimit_rad = 85.0 * std::numbers::pi / 180.0;

// Adds the elements' generalized forces at (t, q, v) to `forces` (7 per
// body, SpatialSystem's layout). 0, or 1 when a value is not finite or a
// bushing is past its angle limit outside a `continued` scope
// (ConstrainedSystem::ContinuePastBounds); then `failure`, when given,
// names the bushing.
int AddForceElementForces(const Model& model, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                          bool continued, SpringAngles* angles, Eigen::VectorXd* forces,
                          std::string* failure = nullptr);

// The rotational springs' and bushings' strain energy (J).
double ForceElementPotentialEnergy(const Model& model, const Eigen::VectorXd& q, SpringAngles* angles);

// The torque rotational spring `spring` applies to its joint's body b about
// the joint axis (N m).
double RotationalSpringTorque(const Model& model, int spring, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                              SpringAngles* angles);

// A bushing's force (N) and couple (N m) on body b, in frame a's axes, and
// its angles theta (rad).
struct BushingLoad {
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d moment_n_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d angles_rad = Eigen::Vector3d::Zero();
};
BushingLoad BushingLoadOf(const Model& model, int bushing, const Eigen::VectorXd& q, const Eigen::VectorXd& v);

// The bushings' angle limits as validity bounds, one per bushing with a
// rotational stiffness or damping, in bushing order:
// cos(theta_y) - cos(kBushingMiddleAngleLimit_rad).
int BushingAngleBoundCount(const Model& model);
void BushingAngleBounds(const Model& model, const Eigen::VectorXd& q, double* g);
std::string BushingAngleBoundReason(const Model& model, int bound, double t, const Eigen::VectorXd& q);

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
