// Redundant constraints of a spatial system, handled by integrating an
// independent set of combinations of the rows.
//
// A mechanism such as Bricard's six-revolute loop has more joint equations
// than the rank of their Jacobian: Phi_q (m x n) has rank r < m along the
// whole motion, and the GGL integrator's augmented matrix
// [M Phi_q^T; Phi_q 0] is singular. Here, at the assembled start, the
// joint and driver rows are replaced by r orthonormal combinations T Phi
// spanning the range of their Jacobian, and the integration uses those.
// Near a pose where the rank stays r, T Phi = 0 and Phi = 0 have the same
// solutions (the left-out direction is implied), so the motion is the
// mechanism's; the analysis checks every row of Phi at every output
// instant. Combinations rather than a subset of the rows: dropping row i
// fails wherever the left null vector y of Phi_q (Phi_q^T y = 0) has
// y_i = 0, which Bricard's linkage reaches within 1.3 s; fixed
// combinations fail only where the range of Phi_q has turned normal to
// the range they were taken at (Bricard's: within 2.5 s), so
// IntegrateWithRedundantRows takes new ones, and restarts, well before.
// docs/physics.md section 8, "Redundant constraints", argues this against
// least-squares multipliers.
//
// Criterion: Euler-parameter normalization rows are kept as they are (each
// acts on its own body's parameters alone, so they are independent of
// each other and of the rest once the rest is projected, below). The
// joint and driver rows' Jacobian B is projected onto the complement of
// the normalization rows (per body, the parameter columns without their
// part along p), and a QR factorization with column pivoting of that
// projection gives its rank (diagonal above kRelativeRankTolerance times
// the largest) and an orthonormal basis U of its range: T = diag(I, U^T).
// Deterministic: the same matrix gives the same T.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "worker/multibody/constrained_system.h"
#include "worker/multibody/forward_dynamics.h"
#include "worker/spatial/spatial_system.h"

namespace mbopt::spatial {

// Relative to the largest pivot of the projected joint rows (whose entries
// are 1 for the point rows and lengths in metres for the others): exact
// redundancy leaves a remainder of rounding size (1e-15), while a row that
// is merely nearly dependent at a nearly singular pose leaves far more.
inline constexpr double kRelativeRankTolerance = 1e-9;

struct IndependentConstraints {
  bool ok = false;  // false: Phi_q was not finite
  int rank = 0;     // of Phi_q
  // r x m: the normalization rows, then U^T on the joint and driver rows.
  Eigen::MatrixXd combination;
};

IndependentConstraints IndependentCombination(const SpatialSystem& system, double t_s, const Eigen::VectorXd& q);

// The system with the constraints T Phi = 0 instead of Phi = 0 (same
// coordinates, mass matrix and forces). Keeps a reference to `full`,
// which must outlive it.
class CombinedConstraintSystem : public multibody::ConstrainedSystem {
 public:
  CombinedConstraintSystem(const multibody::ConstrainedSystem& full, Eigen::MatrixXd combination);

  int num_coordinates() const override { return full_.num_coordinates(); }
  int num_constraints() const override { return static_cast<int>(combination_.rows()); }

  int MassMatrix(const Eigen::VectorXd& q, Eigen::MatrixXd* mass) const override;
  int AppliedForces(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                    Eigen::VectorXd* forces) const override;
  int Constraints(double t, const Eigen::VectorXd& q, Eigen::VectorXd* phi) const override;
  int ConstraintJacobian(double t, const Eigen::VectorXd& q, Eigen::MatrixXd* phi_q) const override;
  int ConstraintTimeDerivative(double t, const Eigen::VectorXd& q, Eigen::VectorXd* phi_t) const override;
  int AccelerationRightSide(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                            Eigen::VectorXd* gamma) const override;
  // The full system's derivatives through the combination (its own when
  // it has them).
  bool has_analytic_derivatives() const override { return full_.has_analytic_derivatives(); }
  int mass_block_size() const override { return full_.mass_block_size(); }
  bool has_exact_state_jacobian() const override { return full_.has_exact_state_jacobian(); }
  int MassTimesAccelerationJacobian(const Eigen::VectorXd& q, const Eigen::VectorXd& a,
                                    Eigen::MatrixXd* jacobian) const override {
    return full_.MassTimesAccelerationJacobian(q, a, jacobian);
  }
  int ConstraintCurvature(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& w,
                          Eigen::MatrixXd* curvature) const override;
  int VelocityConstraintJacobian(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                 Eigen::MatrixXd* jacobian) const override;
  int ForceJacobians(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v, Eigen::MatrixXd* q_q,
                     Eigen::MatrixXd* q_v) const override;
  void DerivativePattern(Pattern* coupling, Pattern* rows) const override;
  std::string FailureReason() const override { return full_.FailureReason(); }
  double DefinedUntil_s() const override { return full_.DefinedUntil_s(); }

 private:
  const multibody::ConstrainedSystem& full_;
  Eigen::MatrixXd combination_;
};

// The varied systems of a sensitivity analysis (multibody::
// ParameterPerturbation) with the nominal system's combination T: the rows
// are the same functions of (q, p) in every variant, so T Phi(q, p +- h)
// differenced is T dPhi/dp, the parameter derivative of the equations
// integrated or solved. T is not a function of p here, and need not be:
// every T whose T Phi_q has full rank has the same solutions (the motion,
// the equilibrium) near the pose, so their derivatives are the same too;
// only the multipliers belong to T. Keeps references to the full
// variants, which must outlive it.
class CombinedPerturbations {
 public:
  CombinedPerturbations(const std::vector<multibody::ParameterPerturbation>& full,
                        const Eigen::MatrixXd& combination);
  const std::vector<multibody::ParameterPerturbation>& parameters() const { return parameters_; }

 private:
  std::vector<std::unique_ptr<CombinedConstraintSystem>> systems_;
  std::vector<multibody::ParameterPerturbation> parameters_;
};

// Restart when the range of the joint rows' Jacobian has turned by more
// than 45 degrees (the cosine of the largest principal angle below this)
// from the range the combination was taken at: fixed combinations become
// singular at 90 degrees, and the integrator's Newton iteration degrades
// on the way there.
inline constexpr double kRestartCosine = 0.7;
// Every row of Phi (m, or dimensionless for the dot products of unit
// vectors; the norm rows unscaled) must hold to this at every check: near
// a pose where Phi_q keeps its rank they hold to the integration tolerance
// (Bricard's linkage: 2e-11 at 1e-10 over 10 s, tests/spatial), past a
// pose where the rank changes (a bifurcation of an overconstrained loop)
// they do not. Far above that drift at any tolerance a scene may ask and
// far below a visible violation.
inline constexpr double kRowBound = 1e-6;
// The range and the rows are checked at the requested instants and at
// least this often over the span, between them (IDAS interpolates there:
// no steps are spent on it).
inline constexpr int kChecksPerSpan = 200;

struct RedundantIntegrationCounters {
  int restarts = 0;          // new combinations taken during the motion
  double largest_row = 0.0;  // of |Phi| at the checks (unscaled norm rows)
};

// Forward dynamics (multibody::IntegrateForward) of a system whose rows
// are redundant, from the assembled start with its combination
// (SpatialAssembly::independent_combination); `at_instant` sees the
// requested instants only, once each. Fails with kAssembly naming the
// row and time when a row leaves kRowBound or the rank changes.
//
// With `sensitivities` (the full variants and the start's derivatives):
// IDAS's forward sensitivities of the combined system, its variants
// combined alike (CombinedPerturbations). At a restart the new
// integration starts from the state's sensitivities reached there, as is:
// they satisfy every row's derivative, Phi_q s_q + Phi_p = 0, not only
// the old combination's. That residual r lies in the range of Phi_q (the
// variants keep the redundancy, so Phi_p = -Phi_q dq/dp), the old
// combination holds T_old r = 0, and T_old is one-to-one on that range
// as long as the range has turned by less than 90 degrees (the restart
// comes at 45): so r = 0, and T_new r = 0. The same for the velocities.
// The multipliers' and accelerations' sensitivities, which do belong to
// the combination, are taken anew as at the start.
spec::AnalysisFailure IntegrateWithRedundantRows(const SpatialSystem& system, const Eigen::MatrixXd& combination,
                                                 double t0_s, const Eigen::VectorXd& q0, const Eigen::VectorXd& v0,
                                                 const std::vector<double>& times_s,
                                                 const multibody::ForwardDynamicsOptions& options,
                                                 const multibody::MotionCallback& at_instant,
                                                 multibody::ForwardDynamicsCounters* counters,
                                                 RedundantIntegrationCounters* redundant,
                                                 const multibody::ForwardSensitivityInput* sensitivities = nullptr);

}  // namespace mbopt::spatial
