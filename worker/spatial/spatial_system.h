// The equations of a spatial multibody Model in absolute coordinates with
// Euler parameters: q = (r, p) per body, r the centre of mass in world axes
// (m) and p its unit quaternion (4 values, body to world), 7 coordinates per
// body; v = dq/dt, as the GGL integrator (worker/multibody/forward_dynamics.h)
// assumes. Implements multibody::ConstrainedSystem, so the planar kernel's
// forward dynamics serve spatial scenes unchanged.
//
// Row layout: one normalization row per body (s (p.p - 1) = 0 with
// s = kNormRowScale, in body order),
// then each joint's rows in joint order (JointEquationCount), then one row
// per driver (an angle's or a slide's). The equations of every joint are written from two kinds of
// building block: the difference of two points and the dot product of two
// vectors fixed in bodies (docs/physics.md, "Spatial scenes").
//
// The mass matrix: 4 L^T J L of the Euler parameters is singular along p.
// The kernel adds (4 tr(J) / 3) p p^T, which makes it positive definite;
// since 2 p^T is the normalization row's Jacobian, the added force lies in
// that row's reaction and only its multiplier changes, not the motion.
//
// Analytic Newton derivatives (spatial_derivatives.cc): the constraints'
// exact second derivatives, the mass matrix's d(M(q) a)/dq, the Euler
// parameters' velocity terms, and the force elements' Jacobians
// (spatial_element_jacobians.h): together the exact state Jacobian, for
// every model.
//
// Immutable after construction but for the rotational springs' turn
// counts (SpringAngles, spatial_force_elements.h): an analysis owns its
// system and evaluates it in one order, so a rerun gives the same bits.
// The model must be valid (Model::Validate) and must outlive the system.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "worker/multibody/constrained_system.h"
#include "worker/spatial/spatial_force_elements.h"
#include "worker/spatial/spatial_model.h"

namespace mbopt::spatial {

class SpatialSystem : public multibody::ConstrainedSystem {
 public:
  explicit SpatialSystem(const Model& model);
  // Keeps a reference to its model: a temporary would die first.
  explicit SpatialSystem(const Model&&) = delete;

  static constexpr int kCoordinatesPerBody = 7;
  // The normalization rows are written s (p.p - 1) = 0. Their multipliers
  // are no physical reaction, yet IDAS's Newton convergence test weighs
  // them with the coordinates' tolerances, and the dense LU (partial
  // pivoting) of the GGL Newton matrix delivers them only to some 1e-6
  // relative: at s = 1 the corrector fails from the first step at
  // tolerances of 1e-9 and tighter (a free body, 1e-8 still passed). At
  // s = 1e6 the multipliers are 1e6 times smaller and held to the absolute
  // tolerance instead: measured to integrate at 1e-10 (1e4 did not).
  // The motion does not depend on s.
  static constexpr double kNormRowScale = 1e6;

  const Model& model() const { return model_; }
  int num_coordinates() const override { return kCoordinatesPerBody * static_cast<int>(model_.bodies.size()); }
  int num_constraints() const override { return num_rows_; }
  int first_row_of_joint(int joint) const { return joint_row_[static_cast<size_t>(joint)]; }
  int row_of_driver(int driver) const { return driver_row_[static_cast<size_t>(driver)]; }
  // What a constraint row belongs to, for messages: "revolute joint 'A'
  // (equation 4)", "the unit norm of body 'B'", "the driver of joint 'A'".
  std::string RowOwner(int row) const;

  int MassMatrix(const Eigen::VectorXd& q, Eigen::MatrixXd* mass) const override;
  // Gravity, spring-dampers, the force elements (spatial_force_elements.h)
  // and the quadratic velocity terms of the Euler parameters' equations
  // (8 L(p')^T J L(p') p).
  int AppliedForces(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                    Eigen::VectorXd* forces) const override;
  int Constraints(double t, const Eigen::VectorXd& q, Eigen::VectorXd* phi) const override;
  int ConstraintJacobian(double t, const Eigen::VectorXd& q, Eigen::MatrixXd* phi_q) const override;
  int ConstraintTimeDerivative(double t, const Eigen::VectorXd& q, Eigen::VectorXd* phi_t) const override;
  int AccelerationRightSide(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                            Eigen::VectorXd* gamma) const override;

  // The Newton matrix's derivatives (spatial_derivatives.cc).
  bool has_analytic_derivatives() const override { return true; }
  int mass_block_size() const override { return kCoordinatesPerBody; }  // one body's (r, p)
  // has_exact_state_jacobian() stays the base's (true with the analytic
  // derivatives): every force element has an analytic Jacobian.
  int MassTimesAccelerationJacobian(const Eigen::VectorXd& q, const Eigen::VectorXd& a,
                                    Eigen::MatrixXd* jacobian) const override;
  int ConstraintCurvature(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& w,
                          Eigen::MatrixXd* curvature) const override;
  int VelocityConstraintJacobian(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                 Eigen::MatrixXd* jacobian) const override;
  int ForceJacobians(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v, Eigen::MatrixXd* q_q,
                     Eigen::MatrixXd* q_v) const override;
  void DerivativePattern(Pattern* coupling, Pattern* rows) const override;

  // The springs' force curves' tables and the bushings' angle limits
  // (spatial_force_elements.h): past one, the analysis ends naming the
  // spring or bushing.
  int num_validity_bounds() const override;
  void ValidityBounds(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v, double* g) const override;
  std::string BoundReason(int bound, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v) const override;
  void ContinuePastBounds(bool on) const override { continue_past_bounds_ = on; }
  // A bushing past its angle limit (outside a continued scope).
  std::string FailureReason() const override { return failure_reason_; }

  // The bodies' initial poses and velocities as coordinates (not yet
  // consistent with the joints: see AssembleSpatial).
  Eigen::VectorXd InitialGuess() const;
  Eigen::VectorXd InitialVelocityGuess() const;

  // Outputs of a state (SI, world axes).
  Eigen::Vector3d PointPosition(const Point& p, const Eigen::VectorXd& q) const;
  Eigen::Vector3d PointVelocity(const Point& p, const Eigen::VectorXd& q, const Eigen::VectorXd& v) const;
  // Body to world, from the coordinates as they are (|p| = 1 within the
  // integration tolerance).
  Eigen::Matrix3d BodyRotation(int body, const Eigen::VectorXd& q) const;
  Eigen::Vector3d AngularVelocity(int body, const Eigen::VectorXd& q, const Eigen::VectorXd& v) const;  // world
  Eigen::Vector3d BodyAngularVelocity(int body, const Eigen::VectorXd& q, const Eigen::VectorXd& v) const;  // body
  // Revolute or cylindrical joint: the rotation coordinate (rad, in (-pi, pi]).
  double JointAngle(int joint, const Eigen::VectorXd& q) const;
  // Prismatic or cylindrical joint: the translation coordinate (m).
  double JointTranslation(int joint, const Eigen::VectorXd& q) const;
  // Their rates (rad/s, m/s).
  double JointAngleRate(int joint, const Eigen::VectorXd& q, const Eigen::VectorXd& v) const;
  double JointTranslationRate(int joint, const Eigen::VectorXd& q, const Eigen::VectorXd& v) const;
  // From the coordinates' second derivatives `a` (world axes, m/s^2).
  Eigen::Vector3d PointAcceleration(const Point& p, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                    const Eigen::VectorXd& a) const;
  double KineticEnergy(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const;
  // Gravity (zero at the world origin) and the springs', rotational
  // springs' and bushings' strain energy.
  double PotentialEnergy(const Eigen::VectorXd& q) const;
  // The torque of rotational spring `spring` on its joint's body b about
  // the joint axis (N m), its angle continued from the system's latest
  // evaluation (spatial_force_elements.h, SpringAngles).
  double RotationalSpringTorque(int spring, const Eigen::VectorXd& q, const Eigen::VectorXd& v) const;
  // Of all bodies about the world origin, world axes (kg m^2/s).
  Eigen::Vector3d AngularMomentum(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const;

 private:
  // The springs' and force elements' generalized forces (no gravity, no
  // velocity terms); 0, or 1 when one is not finite.
  int ElementForces(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v, Eigen::VectorXd* forces) const;
  bool has_force_elements() const;
  void EvaluateRows(double t, const Eigen::VectorXd& q, const Eigen::VectorXd* v, Eigen::VectorXd* phi,
                    Eigen::MatrixXd* phi_q, Eigen::VectorXd* phi_t, Eigen::VectorXd* gamma) const;
  // The row of a driver of a joint's slide (Driver::slide).
  void PutSlideDriverRow(double t, size_t driver, const Eigen::VectorXd& q, const Eigen::VectorXd* v,
                         Eigen::VectorXd* phi, Eigen::MatrixXd* phi_q, Eigen::VectorXd* phi_t,
                         Eigen::VectorXd* gamma) const;

  const Model& model_;
  mutable bool continue_past_bounds_ = false;  // ContinuePastBounds
  mutable SpringAngles spring_angles_;
  mutable std::string failure_reason_;  // FailureReason
  int num_rows_ = 0;
  std::vector<int> joint_row_, driver_row_;
};

}  // namespace mbopt::spatial
