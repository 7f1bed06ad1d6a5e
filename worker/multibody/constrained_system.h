// The equations of motion of a planar constrained mechanical system, as the
// forward-dynamics integrator (forward_dynamics.h) sees them. The mechanism
// kernel (mechanism.h) implements this for a scene's bodies, joints, drivers
// and forces in absolute coordinates (x, y, phi per body); tests implement it
// by hand for textbook systems.
//
//   M(q) a + Phi_q(t, q)^T lambda = Q(t, q, v)      (n equations)
//   Phi(t, q) = 0                                    (m constraints, drivers included)
//   Phi_q v + Phi_t = 0                              (velocity level)
//   Phi_q a = gamma(t, q, v)                         (acceleration level)
//
// q: n coordinates; v = dq/dt; a = dv/dt; lambda: m Lagrange multipliers
// (constraint reactions in generalized form). SI units throughout.
//
// Every evaluation returns the SUNDIALS callback contract: 0 ok, > 0 a
// recoverable failure (the integrator retries with a smaller step, e.g. a
// tabulated curve evaluated outside its range), < 0 unrecoverable. Outputs
// are sized by the callee. Implementations are immutable during an
// integration except for the parameter array (parameters()), which
// sensitivity analysis perturbs in place; every evaluation must read the
// current values from it.
#pragma once

#include <limits>
#include <string>

#include <Eigen/Dense>

namespace mbopt::multibody {

class ConstrainedSystem {
 public:
  virtual ~ConstrainedSystem() = default;

  virtual int num_coordinates() const = 0;  // n
  virtual int num_constraints() const = 0;  // m, driver equations included

  // M(q): n x n, symmetric positive definite.
  virtual int MassMatrix(const Eigen::VectorXd& q, Eigen::MatrixXd* mass) const = 0;
  // Q(t, q, v): applied generalized forces (gravity, springs, dampers, point
  // forces and torques) plus velocity-dependent inertia terms, if any.
  virtual int AppliedForces(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                            Eigen::VectorXd* forces) const = 0;
  // Phi(t, q): m values.
  virtual int Constraints(double t, const Eigen::VectorXd& q, Eigen::VectorXd* phi) const = 0;
  // Phi_q(t, q): m x n.
  virtual int ConstraintJacobian(double t, const Eigen::VectorXd& q, Eigen::MatrixXd* phi_q) const = 0;
  // Phi_t(t, q): m values (non-zero only for rheonomic, i.e. driver, rows).
  virtual int ConstraintTimeDerivative(double t, const Eigen::VectorXd& q, Eigen::VectorXd* phi_t) const = 0;
  // gamma = -(Phi_q v)_q v - 2 Phi_qt v - Phi_tt: m values.
  virtual int AccelerationRightSide(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                    Eigen::VectorXd* gamma) const = 0;

  // A mass matrix block diagonal in consecutive blocks of this many
  // coordinates (0: none declared). The explicit path (explicit_dynamics.h)
  // then factors each block alone and forms Phi_q M^-1 Phi_q^T from the rows
  // that touch each block, instead of dense products over all coordinates.
  virtual int mass_block_size() const { return 0; }

  // The derivatives the integrator's Newton matrix needs beyond M and Phi_q
  // (forward_dynamics.h). A system that returns false here leaves the
  // integrator to form that matrix by difference quotients of its residual,
  // one residual per unknown; the others must implement all three below.
  virtual bool has_analytic_derivatives() const { return false; }
  // Whether those derivatives make the residual's whole state Jacobian, so
  // that sensitivity equations may use them (forward_dynamics.cc,
  // static_equilibrium.cc). A system whose Newton matrix leaves a term out
  // (it only slows Newton's convergence) says false here, and its
  // sensitivities difference the residual instead.
  virtual bool has_exact_state_jacobian() const { return has_analytic_derivatives(); }
  // d(Phi_q^T w)/dq for given multipliers w (m values): n x n, symmetric
  // (the constraints' second derivatives weighted by w).
  virtual int ConstraintCurvature(double /*t*/, const Eigen::VectorXd& /*q*/, const Eigen::VectorXd& /*w*/,
                                  Eigen::MatrixXd* /*curvature*/) const {
    return -1;
  }
  // d(Phi_q v + Phi_t)/dq: m x n.
  virtual int VelocityConstraintJacobian(double /*t*/, const Eigen::VectorXd& /*q*/, const Eigen::VectorXd& /*v*/,
                                         Eigen::MatrixXd* /*jacobian*/) const {
    return -1;
  }
  // d(M(q) a)/dq for given accelerations a (n values): n x n. The default
  // is the zero matrix of a constant mass matrix (the planar kernel's); a
  // system whose M depends on q gives it here, or its Newton matrix and
  // state Jacobian leave it out (then it says false to
  // has_exact_state_jacobian()).
  virtual int MassTimesAccelerationJacobian(const Eigen::VectorXd& /*q*/, const Eigen::VectorXd& /*a*/,
                                            Eigen::MatrixXd* jacobian) const {
    jacobian->setZero(num_coordinates(), num_coordinates());
    return 0;
  }
  // dQ/dq (minus the stiffness) and dQ/dv (minus the damping): n x n each.
  virtual int ForceJacobians(double /*t*/, const Eigen::VectorXd& /*q*/, const Eigen::VectorXd& /*v*/,
                             Eigen::MatrixXd* /*q_q*/, Eigen::MatrixXd* /*q_v*/) const {
    return -1;
  }

  // Which entries of those derivatives can be non-zero in any state: in
  // `coupling` (n x n) for M, dQ/dq, dQ/dv and d(Phi_q^T w)/dq, in `rows`
  // (m x n) for Phi_q and d(Phi_q v + Phi_t)/dq. A sparse Newton matrix's
  // pattern is built from them once per integration. Default: every entry.
  using Pattern = Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>;
  virtual void DerivativePattern(Pattern* coupling, Pattern* rows) const {
    coupling->setConstant(num_coordinates(), num_coordinates(), true);
    rows->setConstant(num_constraints(), num_coordinates(), true);
  }

  // Parameters the equations depend on (stiffnesses, masses, ...), for
  // forward sensitivity analysis by difference quotients. Empty by default.
  virtual int num_parameters() const { return 0; }
  // Why the latest evaluation that returned non-zero failed, when the system
  // knows better than "not finite" (a force curve left its table): says
  // which element and where. Empty otherwise.
  virtual std::string FailureReason() const { return ""; }
  virtual double* parameters() { return nullptr; }

  // The bounds of the model's validity as functions of the state,
  // g_k(t, q, v) > 0 while it holds (a force curve's argument inside its
  // table): the integrator locates where one crosses zero as an event and
  // ends the analysis there, naming the time (BoundReason). While
  // `ContinuePastBounds(true)` is in force the system's equations stay
  // finite a little past a bound (a table continued with its end segment's
  // slope), so that the integrator's trial steps can cross it; outside such
  // a scope, past a bound is a failed evaluation as before.
  virtual int num_validity_bounds() const { return 0; }
  virtual void ValidityBounds(double /*t*/, const Eigen::VectorXd& /*q*/, const Eigen::VectorXd& /*v*/,
                              double* /*g*/) const {}
  virtual std::string BoundReason(int /*bound*/, double /*t*/, const Eigen::VectorXd& /*q*/,
                                  const Eigen::VectorXd& /*v*/) const {
    return "";
  }
  virtual void ContinuePastBounds(bool /*on*/) const {}

  // The latest time the equations are defined at (the end of a tabulated
  // profile's table); +infinity when they hold for all time. The integrator
  // does not step past it.
  virtual double DefinedUntil_s() const { return std::numeric_limits<double>::infinity(); }
};

// Continues a system's equations past its validity bounds for one scope.
class ContinuedPastBounds {
 public:
  explicit ContinuedPastBounds(const ConstrainedSystem& s) : s_(s) { s_.ContinuePastBounds(true); }
  ~ContinuedPastBounds() { s_.ContinuePastBounds(false); }
  ContinuedPastBounds(const ContinuedPastBounds&) = delete;
  ContinuedPastBounds& operator=(const ContinuedPastBounds&) = delete;

 private:
  const ConstrainedSystem& s_;
};

// The largest magnitude of a residual; 0 for a system without constraints
// (a free body), where Eigen's maxCoeff of an empty vector is undefined.
inline double MaxAbs(const Eigen::VectorXd& v) { return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff(); }

}  // namespace mbopt::multibody
