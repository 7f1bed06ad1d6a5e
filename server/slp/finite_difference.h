// The finite-difference step rule of the SLP core (see SlpOptions and
// docs/method.md): which perturbed points to analyse around x0 and how to turn
// their values into a gradient column. Pure functions of scaled values.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "server/slp/options.h"

namespace mbopt::slp {

// Nominal step h = relative_step * max(|x|, floor_fraction * (upper - lower)).
double NominalStep(double x, double lower, double upper, const SlpOptions& options);

// Signed steps to analyse for one variable at x: one step (forward scheme, or
// central near a bound) or two (central: +h and -h). Every x + step lies in
// [lower, upper] and no step is zero.
std::vector<double> PlanSteps(double x, double lower, double upper, const SlpOptions& options);

// The step to retry with after `failed_step` failed: the opposite side when it
// fits in the bounds, else half the step on the same side.
double RetryStep(double x, double lower, double upper, double failed_step);

// One analysed perturbation: x0 + step along one variable, all values
// (objective terms then constraints) stacked.
struct Sample {
  double step = 0;
  Eigen::VectorXd values;
};

// Derivative of every value along the variable. With samples on both sides
// the central quotient (v+ - v-) / (h+ - h-) is used, else the one-sided
// quotient (v - v0) / h of the sample with the largest |h|. No samples: none.
std::optional<Eigen::VectorXd> DerivativeFromSamples(const Eigen::VectorXd& values_x0,
                                                     const std::vector<Sample>& samples);

}  // namespace mbopt::slp
