#include "worker/multibody/kinematic_sensitivity.h"

namespace mbopt::multibody {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// One varied system's equations along the derivative: every equation after
// the positions is evaluated at the same moved coordinates q + sign h dq,
// so their Jacobian (the costly part) is formed once, not once per
// equation.
struct Moved {
  const ConstrainedSystem* system = nullptr;
  double sign = 1.0;
  VectorXd q, v, a;
  MatrixXd phi_q;
};

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
  VectorXd plus, minus, b, gamma, forces;
  MatrixXd mass;
  for (size_t k = 0; k < parameters.size(); ++k) {
    const ParameterPerturbation& dp = parameters[k];
    const double h = dp.step;
    StateSensitivity* out = &(*sensitivities)[k];
    if (dp.plus->Constraints(t, s.q, &plus) != 0 || dp.minus->Constraints(t, s.q, &minus) != 0) return false;
    out->q = -lu.solve((plus - minus) / (2 * h));
    Moved moved[2] = {{dp.plus, 1.0, {}, {}, {}, {}}, {dp.minus, -1.0, {}, {}, {}, {}}};
    VectorXd* r[2] = {&plus, &minus};
    // Phi_q v + Phi_t with v held.
    for (int i = 0; i < 2; ++i) {
      Moved& x = moved[i];
      x.q = s.q + x.sign * h * out->q;
      if (x.system->ConstraintJacobian(t, x.q, &x.phi_q) != 0 || x.system->ConstraintTimeDerivative(t, x.q, &b) != 0) {
        return false;
      }
      *r[i] = x.phi_q * s.v + b;
    }
    out->v = -lu.solve((plus - minus) / (2 * h));
    // Phi_q a - gamma(q, v) with a held.
    for (int i = 0; i < 2; ++i) {
      Moved& x = moved[i];
      x.v = s.v + x.sign * h * out->v;
      if (x.system->AccelerationRightSide(t, x.q, x.v, &gamma) != 0) return false;
      *r[i] = x.phi_q * s.a - gamma;
    }
    out->a = -lu.solve((plus - minus) / (2 * h));
    out->lambda.resize(0);
    if (s.lambda.size() > 0) {
      // Phi_q^T lambda - Q + M a with lambda held.
      for (int i = 0; i < 2; ++i) {
        Moved& x = moved[i];
        x.a = s.a + x.sign * h * out->a;
        if (x.system->MassMatrix(x.q, &mass) != 0 || x.system->AppliedForces(t, x.q, x.v, &forces) != 0) {
          return false;
        }
        *r[i] = x.phi_q.transpose() * s.lambda - forces + mass * x.a;
      }
      out->lambda = -lu_t.solve((plus - minus) / (2 * h));
    }
    if (!(out->q.allFinite() && out->v.allFinite() && out->a.allFinite() && out->lambda.allFinite())) return false;
  }
  return true;
}

}  // namespace mbopt::multibody
