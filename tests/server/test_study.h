// A tiny study for server tests and the analytic "analysis" that answers it
// in place of the engine. The scene is a 1-dof lumped oscillator (so the
// study is valid for the loader), but the fake worker computes its outputs
// from x in closed form; the server does not care how values are produced.
//
// Outputs at the final instant, in scaled variables x = (x1, x2):
//   defl = x1^2 + x2^2        (the objective, minimized)
//   acc  = x1 + x2            (constrained: acc >= 2)
// Optimum x = (1, 1), F = 2; the start is x = (3, 2).
#pragma once

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "mbopt/v1/study.pb.h"

namespace mbopt::testing {

// Physical = scale * x: k [N/m] = 1000 x1, c [N s/m] = 100 x2.
inline constexpr double kStiffnessScale = 1000.0;
inline constexpr double kDampingScale = 100.0;

v1::Study OscillatorStudy(const std::string& name = "oscillator");

struct FakeValues {
  std::vector<double> objective_terms;
  std::vector<double> constraint_values;
};

// The values a worker would report for `study` at scaled design `x`, computed
// through the study's layout (spec/layout.h) from the closed-form outputs.
absl::StatusOr<FakeValues> EvaluateAnalytically(const v1::Study& study, const std::vector<double>& x);

// The oscillator study asking for simulator sensitivities.
v1::Study OscillatorStudyWithSensitivities(const std::string& name = "oscillator");

// What a worker would report as gradients for a task that wants them:
// d(value)/d(x_scaled) of the closed-form outputs (d defl/dx = 2x,
// d acc/dx = 1), through the layout's chain rule (spec/study_gradients.h),
// row-major as in mbopt.v1.TaskResult.
struct FakeGradients {
  std::vector<double> objective_gradients;
  std::vector<double> constraint_gradients;
};
absl::StatusOr<FakeGradients> GradientsAnalytically(const v1::Study& study, const std::vector<double>& x);

}  // namespace mbopt::testing
