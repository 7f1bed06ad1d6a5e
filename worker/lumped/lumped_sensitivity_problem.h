// The lumped model's forward-sensitivity problem as both integration paths
// see it (worker/lumped/lumped_sensitivity.h is the public entry): the model's
// derivatives per parameter, the scratch the right-hand sides share, and the
// two integrations that carry the sensitivities. Internal to worker/solve.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "spec/scene.h"
#include "spec/analysis_report.h"
#include "worker/lumped/lumped_model.h"
#include "worker/budget/analysis_budget.h"
#include "worker/lumped/lumped_sensitivity.h"

namespace mbopt::lumped::sensitivity_internal {

// The model's derivatives with respect to one parameter.
struct ParameterDerivative {
  Eigen::VectorXd mass_diagonal;  // dM/dp
  Eigen::MatrixXd stiffness;      // dK/dp
  Eigen::MatrixXd damping;        // dC/dp
  std::vector<int> stiffness_elements;  // df/dp = -sum g h (these) - sum g h' (the next)
  std::vector<int> damping_elements;
};

// Everything the C callbacks see.
struct SensitivityProblem {
  const LumpedModel* model = nullptr;
  int n = 0;
  Eigen::VectorXd inverse_mass;
  Eigen::MatrixXd minv_k, minv_c;
  std::vector<ParameterDerivative> derivatives;
  Eigen::VectorXd force, rhs;  // scratch
  Eigen::VectorXd zero;        // q = 0, for the ground-input part of a deflection
  // Ground-input part of each element's deflection and its rate at
  // `inputs_time`: every parameter's df/dp is built from these, so one
  // sensitivity right-hand side evaluates the inputs once, not once per
  // parameter.
  std::vector<double> input_deflection, input_rate;
  double inputs_time = std::numeric_limits<double>::quiet_NaN();
  std::string sundials_message;
  // The analysis' deadline and cancel flag (null: none), checked in Rhs;
  // budget_failure says why it stopped the integration.
  const budget::AnalysisBudget* budget = nullptr;
  spec::AnalysisFailure budget_failure;

  void EvaluateInputs(double t) {
    if (t == inputs_time) return;
    for (size_t e = 0; e < model->elements().size(); ++e) {
      input_deflection[e] = model->Deflection(static_cast<int>(e), zero, t);
      input_rate[e] = model->DeflectionRate(static_cast<int>(e), zero, t);
    }
    inputs_time = t;
  }
  // d f / dp_k at the time of the last EvaluateInputs.
  void ForcingDerivative(int k, Eigen::VectorXd* out) const {
    out->setZero(n);
    const ParameterDerivative& d = derivatives[static_cast<size_t>(k)];
    for (int e : d.stiffness_elements) {
      *out -= model->elements()[static_cast<size_t>(e)].gradient *
              input_deflection[static_cast<size_t>(e)];
    }
    for (int e : d.damping_elements) {
      *out -= model->elements()[static_cast<size_t>(e)].gradient *
              input_rate[static_cast<size_t>(e)];
    }
  }
  // d q'' / dp_k from the differentiated equations of motion.
  template <typename Out>
  void AccelerationDerivative(int k, double t, const Eigen::Ref<const Eigen::VectorXd>& q,
                              const Eigen::Ref<const Eigen::VectorXd>& v,
                              const Eigen::Ref<const Eigen::VectorXd>& qddot,
                              const Eigen::Ref<const Eigen::VectorXd>& s,
                              const Eigen::Ref<const Eigen::VectorXd>& sv, Out&& out) {
    const ParameterDerivative& d = derivatives[static_cast<size_t>(k)];
    EvaluateInputs(t);
    ForcingDerivative(k, &rhs);
    rhs -= d.mass_diagonal.cwiseProduct(qddot);
    rhs.noalias() -= d.damping * v;
    rhs.noalias() -= d.stiffness * q;
    out = inverse_mass.cwiseProduct(rhs);
    out.noalias() -= minv_k * s;
    out.noalias() -= minv_c * sv;
  }
};

// Called at every grid instant with the state (q, q') and, for parameter k,
// sensitivity(k) -> (s, s') (2n values each).
using SensitivityRecorder =
    std::function<void(double t, const Eigen::Ref<const Eigen::VectorXd>& state,
                       const std::function<const double*(int)>& sensitivity)>;

// Both return how the integration ended (ok, or the failure) and fill the counters.

// lumped_sensitivity_augmented.cc (the default): the states and all sensitivities as one ODE of size 2n (1 + ns),
// Y = (y, s_1, ..., s_ns), integrated by CVODES without its sensitivity
// module. Its Newton matrix is block lower triangular,
//
//     [ I - gJ                 ]
//     [ -g B_k        I - gJ   ],   B_k = d(sensitivity RHS k)/dy,
//
// so one n x n factorization of M + gC + g^2 K (as IntegrateLumped) solves
// every block: x_0 from b_0, then x_k from b_k + g B_k x_0. The error test
// weighs every component with the tolerances CVodeSensEEtolerances would
// give the sensitivities (rtol, atol_i / pbar_k), i.e. the sensitivities are
// error-controlled as with CVodeSetSensErrCon(SUNTRUE). What this saves over
// the sensitivity module is per-vector overhead: CVODES does each of its
// vector operations once on a 2n (1 + ns) array instead of 1 + ns times on
// 2n-element vectors, which dominates for small n.
spec::AnalysisFailure IntegrateAugmented(SensitivityProblem* p, const spec::IntegratorSettings& settings,
                               const LumpedSensitivityOptions& options, double omega_max,
                               const std::vector<double>& pbar,
                               const std::vector<double>& instants,
                               const SensitivityRecorder& record,
                               spec::AnalysisCounters* counters,
                               LumpedSensitivityCounters* sensitivity_counters);

// lumped_sensitivity_module.cc: CVODES' forward sensitivity module
// (CVodeSensInit), BDF with its dense Newton solver, configured by `options`.
spec::AnalysisFailure IntegrateWithSensitivityModule(SensitivityProblem* p,
                                           const spec::IntegratorSettings& settings,
                                           const LumpedSensitivityOptions& options,
                                           double omega_max, const std::vector<double>& pbar,
                                           const std::vector<double>& instants,
                                           const SensitivityRecorder& record,
                                           spec::AnalysisCounters* counters,
                                           LumpedSensitivityCounters* sensitivity_counters);

}  // namespace mbopt::lumped::sensitivity_internal
