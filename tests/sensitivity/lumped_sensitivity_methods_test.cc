// The two ways SimulateLumpedWithSensitivities integrates the vehicle's
// sensitivities (the augmented system in use, CVODES' sensitivity module
// kept for comparison) against a reference integrated far more tightly.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

#include "spec/io/study_io.h"
#include "worker/lumped/lumped_sensitivity.h"

namespace mbopt::lumped {
namespace {

using Derivatives = std::vector<std::vector<std::vector<double>>>;
using Corrector = LumpedSensitivityOptions::Corrector;

constexpr char kVehicleStudy[] = "examples/vehicle/vehicle.study.textproto";
// The reference: three orders of magnitude tighter than the scene's own
// rtol 1e-8 / atol 1e-11.
constexpr double kReferenceRelativeTolerance = 1e-11;
constexpr double kReferenceAbsoluteTolerance = 1e-14;
// At the scene's tolerances the output derivatives carry the integration
// error of rtol 1e-8 accumulated over some 1700 steps: measured 2.3e-7 (the
// augmented system) and 3.1e-7 (the module) of each series' largest value.
constexpr double kSceneAccuracy = 1e-6;
// Both methods at the reference tolerances: two accurate answers to the same
// equations.
constexpr double kTightAgreement = 1e-8;

struct Vehicle {
  spec::Study study;
  std::vector<double> parameters_si;
  std::vector<int> sensitivity_parameters;
};

Vehicle LoadVehicle(double relative_tolerance, double absolute_tolerance) {
  absl::StatusOr<spec::Study> study = spec::io::LoadStudyFile(kVehicleStudy);
  EXPECT_TRUE(study.ok()) << study.status();
  if (!study.ok()) return {};
  Vehicle v;
  v.study = *study;
  if (relative_tolerance > 0) {
    v.study.scene.integrator.relative_tolerance = relative_tolerance;
    v.study.scene.integrator.absolute_tolerance = absolute_tolerance;
    v.study.scene.integrator.max_steps = 1'000'000;
  }
  std::vector<double> x;
  for (const spec::DesignVariable& var : v.study.variables) {
    x.push_back(var.initial);
    v.sensitivity_parameters.push_back(var.parameter);
  }
  v.parameters_si = v.study.ParameterValuesAt(x);
  return v;
}

Derivatives Derive(const Vehicle& v, const LumpedSensitivityOptions& options) {
  LumpedSensitivityResult r = SimulateLumpedWithSensitivities(
      v.study.scene, v.parameters_si, v.sensitivity_parameters, options);
  EXPECT_TRUE(r.report.ok()) << r.report.failure.reason;
  return r.output_derivatives;
}

LumpedSensitivityOptions Module(Corrector corrector) {
  LumpedSensitivityOptions options;
  options.method = LumpedSensitivityOptions::Method::kCvodesSensitivities;
  options.corrector = corrector;
  return options;
}

// Largest error of a derivative series relative to that series' largest
// |value| in the reference.
double WorstRelativeError(const Derivatives& d, const Derivatives& reference) {
  EXPECT_EQ(d.size(), reference.size());
  double worst = 0.0;
  for (size_t k = 0; k < std::min(d.size(), reference.size()); ++k) {
    for (size_t o = 0; o < reference[k].size(); ++o) {
      double scale = 0.0, error = 0.0;
      for (size_t i = 0; i < reference[k][o].size(); ++i) {
        scale = std::max(scale, std::abs(reference[k][o][i]));
        error = std::max(error, std::abs(d[k][o][i] - reference[k][o][i]));
      }
      if (scale > 0.0) worst = std::max(worst, error / scale);
    }
  }
  return worst;
}

TEST(LumpedSensitivityMethods, AugmentedSystemAndCvodesModuleAgreeAtTightTolerances) {
  const Vehicle tight = LoadVehicle(kReferenceRelativeTolerance, kReferenceAbsoluteTolerance);
  const Derivatives augmented = Derive(tight, {});
  const Derivatives module = Derive(tight, Module(Corrector::kSimultaneous));
  const double disagreement = WorstRelativeError(augmented, module);
  std::cout << "augmented vs module at rtol 1e-11: " << disagreement << "\n";
  EXPECT_LT(disagreement, kTightAgreement);
}

TEST(LumpedSensitivityMethods, EveryMethodMeetsTheSceneAccuracy) {
  const Vehicle tight = LoadVehicle(kReferenceRelativeTolerance, kReferenceAbsoluteTolerance);
  const Derivatives reference = Derive(tight, Module(Corrector::kSimultaneous));
  const Vehicle scene = LoadVehicle(0, 0);
  struct Case {
    const char* name;
    LumpedSensitivityOptions options;
  };
  const Case cases[] = {{"augmented system", {}},
                        {"module, simultaneous", Module(Corrector::kSimultaneous)},
                        {"module, staggered", Module(Corrector::kStaggered)},
                        {"module, staggered1", Module(Corrector::kStaggered1)}};
  for (const Case& c : cases) {
    const double error = WorstRelativeError(Derive(scene, c.options), reference);
    std::cout << c.name << ": worst relative error at the scene tolerances " << error << "\n";
    EXPECT_LT(error, kSceneAccuracy) << c.name;
  }
}

TEST(LumpedSensitivityMethods, CountersCoverTheWholeIntegration) {
  // The module's counters are summed over the restarts at the input's kinks
  // (CVodeReInit zeroes CVODES' own): without its sensitivities in the error
  // test the module takes the steps the states alone need, as the plain
  // analysis does, and the augmented system, which also controls the
  // sensitivities, takes more.
  const Vehicle scene = LoadVehicle(0, 0);
  LumpedSensitivityOptions states_only = Module(Corrector::kSimultaneous);
  states_only.error_control = false;
  const LumpedSensitivityResult module = SimulateLumpedWithSensitivities(
      scene.study.scene, scene.parameters_si, scene.sensitivity_parameters, states_only);
  const LumpedSensitivityResult augmented = SimulateLumpedWithSensitivities(
      scene.study.scene, scene.parameters_si, scene.sensitivity_parameters);
  ASSERT_TRUE(module.report.ok()) << module.report.failure.reason;
  ASSERT_TRUE(augmented.report.ok());
  EXPECT_GT(augmented.report.counters.time_steps, module.report.counters.time_steps);
  EXPECT_GE(module.counters.sensitivity_rhs_evaluations, module.report.counters.time_steps);
  EXPECT_GE(augmented.counters.sensitivity_rhs_evaluations, augmented.report.counters.time_steps);
  EXPECT_GT(augmented.counters.linear_setups, 0);
}

TEST(LumpedSensitivityMethods, StepLimitIsAFailedAnalysisWithReasonForEitherMethod) {
  Vehicle scene = LoadVehicle(0, 0);
  scene.study.scene.integrator.max_steps = 10;  // far fewer than the ~1700 needed
  for (const LumpedSensitivityOptions& options :
       {LumpedSensitivityOptions{}, Module(Corrector::kStaggered)}) {
    const LumpedSensitivityResult r = SimulateLumpedWithSensitivities(
        scene.study.scene, scene.parameters_si, scene.sensitivity_parameters, options);
    EXPECT_FALSE(r.report.ok());
    EXPECT_FALSE(r.report.failure.reason.empty());
    EXPECT_TRUE(r.output_derivatives.empty());
  }
}

}  // namespace
}  // namespace mbopt::lumped
