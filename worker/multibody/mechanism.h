// The equations of a planar multibody Model in absolute coordinates (Haug;
// Nikravesh): q = (x_i, y_i, phi_i) per body, a constant diagonal mass matrix,
// and one block of constraint rows per joint and per driver (docs/physics.md
// lists them with their Jacobians and right-hand sides gamma). Implements
// ConstrainedSystem for the forward-dynamics integrator and evaluates the
// outputs (point positions, joint coordinates, spring forces, energies) of a
// state. Counters prove what was computed: gravity is evaluated only when the
// model declares it.
//
// Row layout: the joints in order (revolute: 2 rows, x and y of marker a minus
// marker b; prismatic: 2, the offset normal to the axis and the relative
// angle; fixed: 3; point on line: 1, the offset normal to the axis), then one
// row per driver.
//
// Not thread-safe (the counters); one Mechanism per analysis. The model must
// be valid (Model::Validate) and must outlive the mechanism.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "worker/multibody/constrained_system.h"
#include "worker/multibody/model.h"

namespace mbopt::multibody {

struct MechanismCounters {
  std::int64_t constraint_evaluations = 0;  // Phi, Phi_t or gamma
  std::int64_t jacobian_evaluations = 0;    // Phi_q
  std::int64_t force_evaluations = 0;       // Q
  std::int64_t gravity_evaluations = 0;     // Q evaluations that included gravity
  std::int64_t mass_matrix_evaluations = 0;
};

class Mechanism : public ConstrainedSystem {
 public:
  explicit Mechanism(const Model& model);
  // The mechanism keeps a reference to its model: a temporary would die
  // before it (the sanitizer build found one such use in a test). Takes
  // every rvalue, const or not, before `const Model&` could.
  explicit Mechanism(const Model&&) = delete;

  const Model& model() const { return model_; }
  int num_coordinates() const override { return 3 * static_cast<int>(model_.bodies.size()); }
  int num_constraints() const override { return num_rows_; }
  int first_row_of_joint(int joint) const { return joint_row_[static_cast<size_t>(joint)]; }
  int row_of_driver(int driver) const { return driver_row_[static_cast<size_t>(driver)]; }
  // The joint (or, for a driver row, the driven joint) a constraint row belongs to.
  int joint_of_row(int row) const { return row_joint_[static_cast<size_t>(row)]; }
  bool is_driver_row(int row) const { return row >= joint_rows_; }

  int MassMatrix(const Eigen::VectorXd& q, Eigen::MatrixXd* mass) const override;
  int AppliedForces(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                    Eigen::VectorXd* forces) const override;
  int Constraints(double t, const Eigen::VectorXd& q, Eigen::VectorXd* phi) const override;
  int ConstraintJacobian(double t, const Eigen::VectorXd& q, Eigen::MatrixXd* phi_q) const override;
  int ConstraintTimeDerivative(double t, const Eigen::VectorXd& q, Eigen::VectorXd* phi_t) const override;
  int AccelerationRightSide(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                            Eigen::VectorXd* gamma) const override;

  // Analytic derivatives (docs/physics.md, "The Newton matrix"): the
  // joints' and drivers' second derivatives, the force elements' stiffness
  // and damping, the co-rotational beams' tangent stiffness.
  bool has_analytic_derivatives() const override { return true; }
  int ConstraintCurvature(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& w,
                          Eigen::MatrixXd* curvature) const override;
  int VelocityConstraintJacobian(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                 Eigen::MatrixXd* jacobian) const override;
  int ForceJacobians(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v, Eigen::MatrixXd* q_q,
                     Eigen::MatrixXd* q_v) const override;
  // Bodies couple through their joints, drivers and force elements.
  void DerivativePattern(Pattern* coupling, Pattern* rows) const override;

  // The initial guess of the coordinates: the bodies' initial poses.
  Eigen::VectorXd InitialGuess() const;

  // Outputs of a state (SI).
  // t_s matters only for moving input points.
  Eigen::Vector2d PointPosition(const Point& p, const Eigen::VectorXd& q, double t_s = 0.0) const;
  Eigen::Vector2d PointVelocity(const Point& p, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                double t_s = 0.0) const;
  Eigen::Vector2d PointAcceleration(const Point& p, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                    const Eigen::VectorXd& a, double t_s = 0.0) const;
  double JointCoordinate(int joint, const Eigen::VectorXd& q) const;
  double JointRate(int joint, const Eigen::VectorXd& q, const Eigen::VectorXd& v) const;
  double SpringLength(int spring, const Eigen::VectorXd& q, double t_s = 0.0) const;
  double SpringTension(int spring, const Eigen::VectorXd& q, const Eigen::VectorXd& v, double t_s = 0.0) const;
  double KineticEnergy(const Eigen::VectorXd& v) const;
  // Gravity (zero at y = 0 for g along -y), the springs' and the beam
  // elements' strain energy.
  double PotentialEnergy(const Eigen::VectorXd& q, double t_s = 0.0) const;
  // Axial force and end moments of beam element `element` (Model::beams),
  // their damping part included when `v` is given (same size as q).
  bool BeamEndLoads(int element, const Eigen::VectorXd& q, const Eigen::VectorXd& v, BeamLoads* loads) const;

  const MechanismCounters& counters() const { return counters_; }
  std::string FailureReason() const override { return failure_; }

  // Two bounds per force curve of a spring (its argument above the table's
  // first x, below its last), in spring order.
  int num_validity_bounds() const override { return static_cast<int>(bounds_.size()); }
  void ValidityBounds(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v, double* g) const override;
  std::string BoundReason(int bound, double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v) const override;
  void ContinuePastBounds(bool on) const override { continue_tables_ = on; }
  // The earliest end of a tabulated profile (drivers, input points, force
  // and torque factors).
  double DefinedUntil_s() const override;

 private:
  // One evaluation of every row: whichever outputs are not null.
  void EvaluateRows(double t, const Eigen::VectorXd& q, const Eigen::VectorXd* v, Eigen::VectorXd* phi,
                    Eigen::MatrixXd* phi_q, Eigen::VectorXd* phi_t, Eigen::VectorXd* gamma) const;
  // One second derivative d2 Phi_row / dq_j dq_k; both (j, k) and (k, j)
  // are listed for j != k.
  struct SecondDerivative {
    int row = 0, j = 0, k = 0;
    double value = 0.0;
  };
  void ConstraintSecondDerivatives(const Eigen::VectorXd& q, std::vector<SecondDerivative>* out) const;
  BeamNodes BeamCoordinates(const BeamElement& e, const Eigen::VectorXd& q) const;
  double ReferenceAngle(int joint) const { return reference_angle_[static_cast<size_t>(joint)]; }
  // A spring's length and its rate dL/dt.
  void SpringLengthAndRate(const SpringDamper& s, const Eigen::VectorXd& q, const Eigen::VectorXd* v, double t,
                           double* length, double* rate) const;

  struct Bound {
    int spring = 0;
    bool velocity_curve = false;  // else the deflection curve
    bool upper = false;           // else the lower end
  };

  const Model& model_;
  int joint_rows_ = 0;
  int num_rows_ = 0;
  std::vector<int> joint_row_, driver_row_, row_joint_;
  std::vector<double> reference_angle_;  // phi_b - phi_a of the initial poses
  mutable MechanismCounters counters_;
  mutable std::string failure_;
  std::vector<Bound> bounds_;
  mutable bool continue_tables_ = false;
};

}  // namespace mbopt::multibody
