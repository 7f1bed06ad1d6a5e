// The dynamic formulation of a lumped scene: integrates the small-motion
// linear equations M q'' + C q' + K q = f(t) (worker/lumped/lumped_model.h)
// from rest at t = 0 with CVODES and reports the requested outputs at the
// scene's grid instants. Only what the outputs need is evaluated: element
// deflections from the state, body accelerations from the equations of
// motion (not by differencing), and nothing at all, not even the
// integration, when the scene requests no output.
//
// The state is y = (q, q'). Newton iterations (BDF, or Adams with Newton)
// solve their linear systems through the second-order structure, an n x n
// factorization of M + gamma C + gamma^2 K, exact since the system matrix is
// constant. The scene's absolute tolerance applies to the coordinates
// (m, rad); the rates get it times the highest natural frequency of the
// undamped system, so that both weigh alike in the error norm. The integrator stops exactly at every instant where an
// input bump starts or ends and restarts there, so the kinks of the forcing
// are never stepped across.
//
// Failure is data: an unusable parameter value, an integrator failure, a
// step or wall-time limit, or a non-finite value gives status kFailed with a
// reason saying what and when.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <string>
#include <vector>

#include "spec/scene.h"
#include "spec/analysis_report.h"
#include "worker/lumped/lumped_model.h"
#include "worker/budget/analysis_budget.h"

namespace mbopt::lumped {

struct LumpedDynamicsOptions {
  bool adams = false;        // Adams-Moulton instead of BDF (non-stiff problems)
  bool fixed_point = false;  // with adams: functional iteration, no linear solves
  // Initial coordinates and rates (SI); empty: at rest. For tests of free
  // responses; analyses of scenes always start at rest.
  Eigen::VectorXd initial_q, initial_qdot;
  // The analysis' deadline and cancel flag, checked in every right-hand
  // side (null: none). The engine passes one (worker/engine).
  const budget::AnalysisBudget* budget = nullptr;
};

// The integration itself: calls `at_instant(t, q, q')` at every instant of
// `instants_s` (ascending, >= 0), starting from t = 0; a failure returned by
// the callback stops the integration. Returns how the integration ended;
// `counters` receives the integrator's counters either way.
using LumpedInstantCallback =
    std::function<spec::AnalysisFailure(double t_s, const Eigen::VectorXd& q, const Eigen::VectorXd& qdot)>;
spec::AnalysisFailure IntegrateLumped(const LumpedModel& model, const std::vector<double>& instants_s,
                            const spec::IntegratorSettings& settings,
                            const LumpedDynamicsOptions& options,
                            const LumpedInstantCallback& at_instant,
                            spec::AnalysisCounters* counters);

// `scene.model` must hold a LumpedModel; `parameter_values_si` has one value
// per scene parameter. Fills formulation kDynamic, the grid, the outputs in
// scene order and the integrator counters (not the wall time).
spec::AnalysisReport SimulateLumped(const spec::Scene& scene,
                                      const std::vector<double>& parameter_values_si,
                                      const LumpedDynamicsOptions& options = {});

}  // namespace mbopt::lumped
