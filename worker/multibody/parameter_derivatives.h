// Exact partial derivatives of a mechanism's equations with respect to one
// scene parameter, for sensitivity analysis (forward_dynamics.h,
// static_equilibrium.h).
//
// The equations are linear in most of the coefficients a design varies: the
// mass matrix in the bodies' masses and inertias, the applied forces in the
// masses (gravity), the springs' stiffness, damping and actuator force, the
// rotational springs' stiffness and damping, the point forces and torques.
// When a parameter changes only such coefficients (whatever expressions it
// goes through), dM/dp and dQ/dp are the mass matrix and the applied forces
// of a "derivative model": the nominal model's geometry with each coefficient
// replaced by its derivative and every other force element left out. The
// constraints do not depend on such a parameter. The coefficients'
// derivatives come from the model compiled at p +- h (exact for expressions
// linear in p, to round-off).
//
// A parameter that changes anything else (a marker, a length, a free
// length, a driver's profile, a flexible link's section, gravity) has no
// derivative model here: callers difference the equations of the models at
// p +- h instead (the equations alone, at a fixed state).
#pragma once

#include <memory>

#include <Eigen/Dense>

#include "worker/multibody/ggl_residual.h"
#include "worker/multibody/mechanism.h"
#include "worker/multibody/model.h"
#include "worker/multibody/motion.h"

namespace mbopt::multibody {

class ParameterDerivativeModel {
 public:
  // Null when `plus` or `minus` differs from `nominal` in anything but the
  // coefficients above; `step` is h (the models are at p + h and p - h).
  static std::unique_ptr<ParameterDerivativeModel> Of(const Model& nominal, const Model& plus, const Model& minus,
                                                      double step);

  // MassMatrix is dM/dp, AppliedForces dQ/dp; the constraints are the
  // nominal ones (their derivative is zero, not these).
  const Mechanism& system() const { return *mechanism_; }
  const Model& model() const { return model_; }

 private:
  ParameterDerivativeModel() = default;
  Model model_;
  std::unique_ptr<Mechanism> mechanism_;  // refers to model_: never moved
};

// dF/dp_k of the GGL residual (ggl_residual.h) at a fixed (t, y, y'): with
// a derivative model, (0, dM/dp v' - dQ/dp, 0, 0); else the central
// difference of the residuals of `dp.plus` and `dp.minus`. The SUNDIALS
// callback contract (0 ok).
int GglParameterDerivative(const ParameterPerturbation& dp, double t, const Eigen::Ref<const Eigen::VectorXd>& y,
                           const Eigen::Ref<const Eigen::VectorXd>& y_dot, GglWorkspace* work,
                           Eigen::Ref<Eigen::VectorXd> out);

// dG/dp_k of the static equilibrium equations G(q, lambda) = (Q(t, q, 0) -
// Phi_q^T lambda, Phi(t, q)) (static_equilibrium.h) at a fixed (q, lambda):
// (dQ/dp, 0) with a derivative model, else a central difference of the
// variants' G.
int StaticParameterDerivative(const ParameterPerturbation& dp, double t, const Eigen::VectorXd& q,
                              const Eigen::VectorXd& lambda, Eigen::VectorXd* out);

}  // namespace mbopt::multibody
