// KinematicSolver: position, velocity and acceleration analysis of a driven
// planar linkage in natural coordinates (the positions of the non-ground
// joints are the unknowns), for any number of bars and joints as long as the
// driven mechanism has zero degrees of freedom.
//
// Constraints: one per bar, (|r_b - r_a|^2 - L^2) / (2 L) = 0 (a length error
// in m), except the driven bar, whose moving joint is prescribed:
// r_driven = r_pivot + L (cos a(t), sin a(t)), a(t) = a0 + omega t.
// Bars with both joints on the ground carry no constraint.
//
// The solver follows the assembly branch continuously: the driver angle is
// advanced in sub-steps of at most kMaxDriverStepRad, each solved by Newton
// from a velocity predictor; the sign of det(Phi_q) (which changes only
// through a singular, locking position) must stay that of the start. Anything
// else -- no assembly, a singular Jacobian, Newton failure, a branch flip --
// is a failed outcome whose reason names the time and the joint or bar.
//
// Owns its work buffers; borrows the LinkageSystem, which must outlive it.
#pragma once

#include "spec/analysis_outcome.h"

#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "worker/model/linkage_model.h"

namespace mbopt::solve {

// The linkage at one instant; indexed by joint (ground joints included).
struct LinkageState {
  double time_s = 0.0;
  double driver_angle_rad = 0.0;
  std::vector<Eigen::Vector2d> position_m, velocity_m_per_s, acceleration_m_per_s2;
  double branch_sign = 0.0;  // sign of det(Phi_q)

  // Rigid-link quantities from the joint states.
  Eigen::Vector2d LinkVector(const model::LinkageLink& link) const;  // r_b - r_a
  double LinkAngle(const model::LinkageLink& link) const;            // rad, atan2
  double LinkAngularVelocity(const model::LinkageLink& link) const;  // rad/s
  double LinkAngularAcceleration(const model::LinkageLink& link) const;  // rad/s^2
};

// Outcomes of the kinematic, kinetostatic and elastodynamic solvers: the
// project's one failure vocabulary (spec/analysis_outcome.h), so a solver's
// failure reaches the user with its kind.
using KinematicOutcome = spec::AnalysisFailure;

class KinematicSolver {
 public:
  static constexpr double kMaxDriverStepRad = 2.0 * std::numbers::pi / 180.0;

  explicit KinematicSolver(const model::LinkageSystem& system);

  // Checks the degree-of-freedom count and assembles the start configuration
  // (t = 0) from the given joint positions. Must succeed before AdvanceTo.
  KinematicOutcome Start();

  // Follows the branch from the current instant to t_s (>= current time).
  // When `trail` is non-null every sub-step state is appended to it.
  KinematicOutcome AdvanceTo(double t_s, std::vector<LinkageState>* trail = nullptr);

  // Solves at t_s starting from `near`, a state on the branch close in time
  // (e.g. from a trail); fails if Newton does not converge or the branch
  // changes. Does not change the current state.
  KinematicOutcome SolveFrom(const LinkageState& near, double t_s, LinkageState* out);

  const LinkageState& state() const { return state_; }
  std::int64_t position_solves() const { return position_solves_; }
  std::int64_t newton_iterations() const { return newton_iterations_; }

 private:
  enum class NewtonResult { kConverged, kNoConvergence, kSingular };

  double DriverAngle(double t_s) const;
  void Residual(const Eigen::VectorXd& q, double angle, Eigen::VectorXd* r) const;
  void Jacobian(const Eigen::VectorXd& q, Eigen::MatrixXd* jac) const;
  NewtonResult Newton(Eigen::VectorXd* q, double angle, int max_iterations);
  // Fills velocities and accelerations of `s` from q at `angle`; false if the
  // Jacobian is singular.
  bool Complete(const Eigen::VectorXd& q, double t_s, LinkageState* s);
  void ToState(const Eigen::VectorXd& q, LinkageState* s) const;
  void FromState(const LinkageState& s, Eigen::VectorXd* q, Eigen::VectorXd* qdot) const;
  std::string WorstConstraint(const Eigen::VectorXd& q, double angle) const;
  std::string NullMotionJoint() const;  // from the last factorized Jacobian

  const model::LinkageSystem& sys_;
  std::vector<int> joint_dof_;       // first unknown of a joint; -1 for ground
  std::vector<int> constrained_links_;  // links with a length constraint
  int num_unknowns_ = 0;
  double length_scale_m_ = 1.0;
  double driven_length_m_ = 0.0;
  bool started_ = false;
  bool lu_at_solution_ = false;  // lu_ factorizes Phi_q at the last Newton solution

  LinkageState state_;
  Eigen::VectorXd q_, qdot_, r_, dq_, rhs_, predicted_;
  Eigen::MatrixXd jac_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  std::int64_t position_solves_ = 0;
  std::int64_t newton_iterations_ = 0;
};

}  // namespace mbopt::solve
