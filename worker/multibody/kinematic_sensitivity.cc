#include "worker/multibody/kinematic_sensitivity.h"

namespace mbopt::multibody {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// Phi_q(q) x + b(q): the velocity (x = v, b = Phi_t) and acceleration
// (x = a, b = -gamma(q, v)) equations of `s`.
int VelocityEquation(const ConstrainedSystem& s, double t, const VectorXd& q, const VectorXd& v, VectorXd* r) {
  MatrixXd phi_q;
  VectorXd phi_t;
  if (int flag = s.ConstraintJacobian(t, q, &phi_q); flag != 0) return flag;
  if (int flag = s.ConstraintTimeDerivative(t, q, &phi_t); flag != 0) return flag;
  *r = phi_q * v + phi_t;
  return 0;
}

int AccelerationEquation(const ConstrainedSystem& s, double t, const VectorXd& q, const VectorXd& v,
                         const VectorXd& a, VectorXd* r) {
  MatrixXd phi_q;
  VectorXd gamma;
  if (int flag = s.ConstraintJacobian(t, q, &phi_q); flag != 0) return flag;
  if (int flag = s.AccelerationRightSide(t, q, v, &gamma); flag != 0) return flag;
  *r = phi_q * a - gamma;
  return 0;
}

int ForceEquation(const ConstrainedSystem& s, double t, const VectorXd& q, const VectorXd& v, const VectorXd& a,
                  const VectorXd& lambda, VectorXd* r) {
  MatrixXd phi_q, mass;
  VectorXd forces;
  if (int flag = s.ConstraintJacobian(t, q, &phi_q); flag != 0) return flag;
  if (int flag = s.MassMatrix(q, &mass); flag != 0) return flag;
  if (int flag = s.AppliedForces(t, q, v, &forces); flag != 0) return flag;
  *r = phi_q.transpose() * lambda - forces + mass * a;
  return 0;
}

}  // namespace

bool KinematicStateSensitivities(const ConstrainedSystem& system, const std::vector<ParameterPerturbation>& parameters,
                                 const MotionSample& s, std::vector<StateSensitivity>* sensitivities) {
  const double t = s.t_s;
  MatrixXd phi_q;
  if (system.ConstraintJacobian(t, s.q, &phi_q) != 0 || phi_q.rows() != phi_q.cols()) return false;
  const Eigen::PartialPivLU<MatrixXd> lu(phi_q);
  Eigen::PartialPivLU<MatrixXd> lu_t;
  if (s.lambda.size() > 0) lu_t.compute(phi_q.transpose());
  sensitivities->resize(parameters.size());
  VectorXd plus, minus;
  for (size_t k = 0; k < parameters.size(); ++k) {
    const ParameterPerturbation& dp = parameters[k];
    const double h = dp.step;
    StateSensitivity* out = &(*sensitivities)[k];
    if (dp.plus->Constraints(t, s.q, &plus) != 0 || dp.minus->Constraints(t, s.q, &minus) != 0) return false;
    out->q = -lu.solve((plus - minus) / (2 * h));
    if (VelocityEquation(*dp.plus, t, s.q + h * out->q, s.v, &plus) != 0 ||
        VelocityEquation(*dp.minus, t, s.q - h * out->q, s.v, &minus) != 0) {
      return false;
    }
    out->v = -lu.solve((plus - minus) / (2 * h));
    if (AccelerationEquation(*dp.plus, t, s.q + h * out->q, s.v + h * out->v, s.a, &plus) != 0 ||
        AccelerationEquation(*dp.minus, t, s.q - h * out->q, s.v - h * out->v, s.a, &minus) != 0) {
      return false;
    }
    out->a = -lu.solve((plus - minus) / (2 * h));
    out->lambda.resize(0);
    if (s.lambda.size() > 0) {
      if (ForceEquation(*dp.plus, t, s.q + h * out->q, s.v + h * out->v, s.a + h * out->a, s.lambda, &plus) != 0 ||
          ForceEquation(*dp.minus, t, s.q - h * out->q, s.v - h * out->v, s.a - h * out->a, s.lambda, &minus) !=
              0) {
        return false;
      }
      out->lambda = -lu_t.solve((plus - minus) / (2 * h));
    }
    if (!(out->q.allFinite() && out->v.allFinite() && out->a.allFinite() && out->lambda.allFinite())) return false;
  }
  return true;
}

}  // namespace mbopt::multibody
